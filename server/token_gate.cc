#include "token_gate.h"

#include "json_log.h"
#include "service_error.h"

namespace hj::server {

namespace {

// Calls anyone may make: the health service and server reflection.
bool open_to_all(const std::string& path) {
  return path.rfind("/grpc.health.v1.Health/", 0) == 0 || path.rfind("/grpc.reflection.", 0) == 0;
}

std::optional<std::string> header(const grpc::AuthMetadataProcessor::InputMetadata& metadata, const char* key) {
  const auto found = metadata.find(key);
  if (found == metadata.end()) return std::nullopt;
  return std::string(found->second.data(), found->second.size());
}

}  // namespace

grpc::Status TokenGate::Process(const InputMetadata& auth_metadata, grpc::AuthContext*, OutputMetadata*,
                                OutputMetadata*) {
  const std::string path = header(auth_metadata, ":path").value_or("");
  if (open_to_all(path)) return grpc::Status::OK;
  try {
    auth_.authorize(header(auth_metadata, "authorization"), Role::kPreview, path);
    return grpc::Status::OK;
  } catch (const ServiceError& e) {
    log_event("rpc_refused", {{"method", path}, {"code", int(e.status().error_code())}, {"error", e.what()}});
    return e.status();
  }
}

}  // namespace hj::server
