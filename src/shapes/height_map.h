// A goal shape as imported: a top-view height image in the file's own units,
// before it is fitted to an array (resample.h). Importers translate files into
// it at the edge of the library (docs/architecture.md, "shapes").
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace hj {

// Where a map's pixels lie on the Earth (GDAL's convention): the point at
// pixel column x, row y (x, y continuous, (0, 0) the top-left corner of the
// top-left pixel) has map coordinates
//   X = geotransform[0] + x geotransform[1] + y geotransform[2]
//   Y = geotransform[3] + x geotransform[4] + y geotransform[5]
// in the coordinate reference system crs_wkt (OGC WKT; for longitude /
// latitude in degrees on WGS 84, X = longitude and Y = latitude).
struct GeoReference {
  std::array<double, 6> geotransform{0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  std::string crs_wkt;
};

struct HeightMap {
  // (rows x cols): row 0 = the image's top (north), column 0 = its left (west);
  // NaN = no data; source units (metres for a DEM, grey levels for an image).
  // A CSV's rows are taken in file order: a DEM stored south-up must be
  // flipped by the caller (see the DEM's JSON, "north_up_numpy").
  Eigen::MatrixXd z;
  std::string source;  // where it came from, for messages: a path, plus any crop
  // Height of the NaN pixels when fitting to an array, where they mean "no
  // surface here" rather than "no data": a mesh's top view sets 0, the floor
  // the part stands on. Unset (a DEM's no-data): take the nearest valid value.
  std::optional<double> uncovered_height;
  // Set by importers of georeferenced data (GeoTIFF, SRTM .hgt, a north-up
  // CSV whose sidecar JSON has a "georef" block); kept by crop().
  std::optional<GeoReference> georef;
  // The unit of z when known: "m" for elevations (importers convert feet and
  // apply a band's scale and offset), empty when the file does not say.
  std::string units;
};

// A goal file that cannot be read. The message names the file and what is
// wrong with it.
class ImportError : public std::runtime_error {
 public:
  ImportError(const std::filesystem::path& file, const std::string& problem)
      : std::runtime_error("cannot import goal \"" + file.string() + "\": " + problem), file_(file) {}
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

}  // namespace hj
