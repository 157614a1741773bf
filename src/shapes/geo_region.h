// A region of interest in longitude / latitude for a georeferenced goal
// (GeoTIFF, SRTM .hgt, a CSV with a sidecar georef): converted to pixels
// through the goal's geotransform, via GDAL/OGR when its CRS is projected.
#pragma once

#include <string>

#include "shapes/height_map.h"
#include "shapes/region.h"

namespace hj {

// Degrees on WGS 84: west, south, east, north edges.
struct LonLatBox {
  double lon0 = 0.0, lat0 = 0.0, lon1 = 0.0, lat1 = 0.0;
};

// Parses "lon0,lat0,lon1,lat1" (degrees, lon0 < lon1, lat0 < lat1, latitudes
// within +-90, longitudes within +-180).
// @throws std::invalid_argument naming the text and what is wrong.
LonLatBox parse_lonlat_box(const std::string& text);

// The pixels of `map` the box covers (every pixel it touches), its georef
// kept; the box's edges are sampled and transformed into the map's CRS, so a
// projected map gets the pixel rectangle around the curved outline.
// @throws std::invalid_argument when the map is not georeferenced, its CRS
//         is unknown to GDAL, the box lies wholly or partly outside the data
//         (the message gives the data's extent in longitude / latitude), or
//         the region holds only no-data pixels.
HeightMap crop_lonlat(const HeightMap& map, const LonLatBox& box);
// The pixel region crop_lonlat takes (fractions = false); throws as it does,
// except for a region of only no-data pixels (crop() finds those).
Region lonlat_pixel_region(const HeightMap& map, const LonLatBox& box);

}  // namespace hj
