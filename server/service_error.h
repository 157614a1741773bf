// An error a handler returns to its caller as a gRPC status: the code says
// what kind (docs: proto/README.md, "Status codes"), the message what is wrong.
#pragma once

#include <grpcpp/support/status.h>

#include <stdexcept>
#include <string>

namespace hj::server {

class ServiceError : public std::runtime_error {
 public:
  ServiceError(grpc::StatusCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  grpc::StatusCode code() const { return code_; }
  grpc::Status status() const { return grpc::Status(code_, what()); }

 private:
  grpc::StatusCode code_;
};

// The status for an exception escaping a handler's work: ServiceError keeps
// its code, bad input (std::invalid_argument, hj::ImportError,
// hj::ParamsError) is INVALID_ARGUMENT, a failing job database (StoreError)
// UNAVAILABLE, anything else INTERNAL.
grpc::Status status_from_current_exception();

}  // namespace hj::server
