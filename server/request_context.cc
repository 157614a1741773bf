#include "request_context.h"

#include "json_log.h"
#include "service_error.h"

namespace hj::server {

RequestContext::RequestContext(grpc::ServerContext* context, std::string method)
    : context_(context), method_(std::move(method)), id_(new_request_id()) {
  context_->AddInitialMetadata("x-request-id", id_);
}

const Caller& RequestContext::authorize(const Authenticator& auth, Role role, const std::string& action) {
  std::optional<std::string> header;
  const auto& metadata = context_->client_metadata();
  if (const auto found = metadata.find("authorization"); found != metadata.end())
    header = std::string(found->second.data(), found->second.size());
  caller_ = auth.authorize(header, role, action);
  return caller_;
}

grpc::Status RequestContext::finish(const std::function<void()>& body) {
  grpc::Status status;
  try {
    body();
  } catch (...) {
    status = status_from_current_exception();
  }
  nlohmann::json line = {{"request_id", id_},
                         {"method", method_},
                         {"peer", context_->peer()},
                         {"caller", caller_.name},
                         {"code", int(status.error_code())},
                         {"ms", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count()}};
  if (!status.ok()) line["error"] = status.error_message();
  line.update(fields_);
  log_event("rpc", std::move(line));
  return status;
}

}  // namespace hj::server
