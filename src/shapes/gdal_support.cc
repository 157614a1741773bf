#include "shapes/gdal_support.h"

#include <cpl_error.h>
#include <gdal.h>

#include <mutex>

namespace hj::gdal {

void ensure_registered() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

QuietErrors::QuietErrors() {
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
}

QuietErrors::~QuietErrors() { CPLPopErrorHandler(); }

std::string QuietErrors::message() const {
  const char* m = CPLGetLastErrorMsg();
  return m ? m : "";
}

}  // namespace hj::gdal
