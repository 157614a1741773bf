// The little GDAL glue the GeoTIFF importer and the longitude/latitude region
// share: driver registration once, and GDAL's error text captured instead of
// printed.
#pragma once

#include <string>

namespace hj::gdal {

// Registers GDAL's drivers (once, thread-safe).
void ensure_registered();

// While alive, GDAL errors on this thread are kept, not printed; message()
// is the last one ("" if none).
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;
  std::string message() const;
};

}  // namespace hj::gdal
