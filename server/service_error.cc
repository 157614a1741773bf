#include "service_error.h"

#include "calib/model_params.h"
#include "job_store.h"
#include "shapes/height_map.h"

namespace hj::server {

grpc::Status status_from_current_exception() {
  try {
    throw;
  } catch (const ServiceError& e) {
    return e.status();
  } catch (const std::invalid_argument& e) {
    return {grpc::StatusCode::INVALID_ARGUMENT, e.what()};
  } catch (const ImportError& e) {
    return {grpc::StatusCode::INVALID_ARGUMENT, e.what()};
  } catch (const ParamsError& e) {
    return {grpc::StatusCode::INVALID_ARGUMENT, e.what()};
  } catch (const StoreError& e) {
    return {grpc::StatusCode::UNAVAILABLE, e.what()};
  } catch (const std::exception& e) {
    return {grpc::StatusCode::INTERNAL, e.what()};
  }
}

}  // namespace hj::server
