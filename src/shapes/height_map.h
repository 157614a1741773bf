// A goal shape as imported: a top-view height image in the file's own units,
// before it is fitted to an array (resample.h). Importers translate files into
// it at the edge of the library (docs/architecture.md, "shapes").
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace hj {

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
