// The frame of every handler: a request id (logged and returned in the
// `x-request-id` initial metadata), the caller, and one JSON log line when
// the call ends with its status and duration. Exceptions from the body
// become the status (status_from_current_exception).
#pragma once

#include <grpcpp/server_context.h>

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "auth.h"

namespace hj::server {

class RequestContext {
 public:
  RequestContext(grpc::ServerContext* context, std::string method);

  // Authorises the caller by its `authorization` metadata; throws ServiceError.
  const Caller& authorize(const Authenticator& auth, Role role, const std::string& action);
  const Caller& caller() const { return caller_; }
  const std::string& id() const { return id_; }
  // Adds a field to the call's log line.
  void note(const std::string& key, nlohmann::json value) { fields_[key] = std::move(value); }

  // Runs body, logs, returns its status.
  grpc::Status finish(const std::function<void()>& body);

 private:
  grpc::ServerContext* context_;
  std::string method_, id_;
  Caller caller_;
  nlohmann::json fields_ = nlohmann::json::object();
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace hj::server
