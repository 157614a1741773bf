#include "shapes/geo_region.h"

#include <gdal.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "shapes/gdal_support.h"
#include "shapes/region.h"

namespace hj {
namespace {

std::string describe(const LonLatBox& b) {
  std::ostringstream s;
  s.precision(10);
  s << "lon/lat " << b.lon0 << "," << b.lat0 << "," << b.lon1 << "," << b.lat1;
  return s.str();
}

struct Transforms {
  std::unique_ptr<OGRCoordinateTransformation> to_map, to_lonlat;  // null: the map is in lon/lat already
};

Transforms make_transforms(const HeightMap& map) {
  gdal::ensure_registered();
  gdal::QuietErrors errors;
  OGRSpatialReference lonlat, target;
  lonlat.importFromEPSG(4326);
  lonlat.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  if (map.georef->crs_wkt.empty() || target.SetFromUserInput(map.georef->crs_wkt.c_str()) != OGRERR_NONE)
    throw std::invalid_argument("goal \"" + map.source + "\": its coordinate reference system " +
                                (map.georef->crs_wkt.empty() ? std::string("is not given") : "is not understood by GDAL: " + errors.message()) +
                                ", so a longitude/latitude region cannot be placed on it");
  target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  Transforms t;
  if (target.IsGeographic() && target.IsSame(&lonlat)) return t;
  t.to_map.reset(OGRCreateCoordinateTransformation(&lonlat, &target));
  t.to_lonlat.reset(OGRCreateCoordinateTransformation(&target, &lonlat));
  if (!t.to_map || !t.to_lonlat)
    throw std::invalid_argument("goal \"" + map.source + "\": no transformation from longitude/latitude to its CRS: " +
                                errors.message());
  return t;
}

}  // namespace

LonLatBox parse_lonlat_box(const std::string& text) {
  std::vector<double> v;
  std::istringstream in(text);
  for (std::string field; std::getline(in, field, ',');) {
    std::size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || field.find_first_not_of(" \t", used) != std::string::npos || !std::isfinite(x))
      throw std::invalid_argument("region \"" + text + "\": \"" + field + "\" is not a number; expected lon0,lat0,lon1,lat1");
    v.push_back(x);
  }
  if (v.size() != 4)
    throw std::invalid_argument("region \"" + text + "\": expected four numbers lon0,lat0,lon1,lat1 (degrees), got " +
                                std::to_string(v.size()));
  const LonLatBox b{v[0], v[1], v[2], v[3]};
  const auto fail = [&](const std::string& what) { throw std::invalid_argument("region \"" + text + "\": " + what); };
  for (double lat : {b.lat0, b.lat1})
    if (std::abs(lat) > 90.0) fail("latitudes must lie within -90..90 degrees");
  for (double lon : {b.lon0, b.lon1})
    if (std::abs(lon) > 180.0) fail("longitudes must lie within -180..180 degrees");
  if (!(b.lon1 > b.lon0)) fail("lon1 must be east of (greater than) lon0");
  if (!(b.lat1 > b.lat0)) fail("lat1 must be north of (greater than) lat0");
  return b;
}

Region lonlat_pixel_region(const HeightMap& map, const LonLatBox& box) {
  if (!map.georef)
    throw std::invalid_argument("goal \"" + map.source +
                                "\" is not georeferenced (a GeoTIFF, an SRTM .hgt tile or a CSV whose sidecar JSON has "
                                "a georef block is), so it has no longitude/latitude region; use a pixel or fraction region");
  const Transforms t = make_transforms(map);
  const auto& gt = map.georef->geotransform;
  double inv[6];
  if (!GDALInvGeoTransform(const_cast<double*>(gt.data()), inv))
    throw std::invalid_argument("goal \"" + map.source + "\": its geotransform cannot be inverted");
  const double cols = double(map.z.cols()), rows = double(map.z.rows());

  // The data's extent in lon/lat, for messages: its corners and edge midpoints.
  double west = INFINITY, east = -INFINITY, south = INFINITY, north = -INFINITY;
  for (double fx : {0.0, 0.5, 1.0})
    for (double fy : {0.0, 0.5, 1.0}) {
      double x = gt[0] + fx * cols * gt[1] + fy * rows * gt[2], y = gt[3] + fx * cols * gt[4] + fy * rows * gt[5];
      if (t.to_lonlat && !t.to_lonlat->Transform(1, &x, &y)) continue;
      west = std::min(west, x), east = std::max(east, x), south = std::min(south, y), north = std::max(north, y);
    }
  std::ostringstream extent;
  extent.precision(8);
  extent << "the data covers lon " << west << ".." << east << ", lat " << south << ".." << north;

  // The box's outline, sampled, in pixel coordinates.
  constexpr int kSamples = 16;
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  for (int k = 0; k <= 4 * kSamples; ++k) {
    const int edge = std::min(k / kSamples, 3);
    const double f = double(k - edge * kSamples) / kSamples;
    double lon = edge == 0 ? box.lon0 + f * (box.lon1 - box.lon0) : edge == 1 ? box.lon1 : edge == 2 ? box.lon1 - f * (box.lon1 - box.lon0) : box.lon0;
    double lat = edge == 0 ? box.lat0 : edge == 1 ? box.lat0 + f * (box.lat1 - box.lat0) : edge == 2 ? box.lat1 : box.lat1 - f * (box.lat1 - box.lat0);
    if (t.to_map && !t.to_map->Transform(1, &lon, &lat))
      throw std::invalid_argument("region " + describe(box) + " cannot be transformed into the CRS of goal \"" +
                                  map.source + "\"");
    const double px = inv[0] + lon * inv[1] + lat * inv[2], py = inv[3] + lon * inv[4] + lat * inv[5];
    x_min = std::min(x_min, px), x_max = std::max(x_max, px), y_min = std::min(y_min, py), y_max = std::max(y_max, py);
  }
  constexpr double kSlack = 1e-6;  // pixels: a box on the data's edge is inside
  if (x_max <= kSlack || y_max <= kSlack || x_min >= cols - kSlack || y_min >= rows - kSlack)
    throw std::invalid_argument("region " + describe(box) + " lies outside goal \"" + map.source + "\"; " + extent.str());
  if (x_min < -kSlack || y_min < -kSlack || x_max > cols + kSlack || y_max > rows + kSlack)
    throw std::invalid_argument("region " + describe(box) + " reaches outside goal \"" + map.source + "\"; " + extent.str());
  Region pixels;
  pixels.fractions = false;
  pixels.x0 = std::max(0.0, std::floor(x_min + kSlack));
  pixels.y0 = std::max(0.0, std::floor(y_min + kSlack));
  pixels.x1 = std::min(cols, std::max(pixels.x0 + 1, std::ceil(x_max - kSlack)));
  pixels.y1 = std::min(rows, std::max(pixels.y0 + 1, std::ceil(y_max - kSlack)));
  return pixels;
}

HeightMap crop_lonlat(const HeightMap& map, const LonLatBox& box) {
  HeightMap out = crop(map, lonlat_pixel_region(map, box));
  out.source += " [" + describe(box) + "]";
  return out;
}

}  // namespace hj
