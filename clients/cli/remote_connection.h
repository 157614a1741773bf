// What every `hapticjam remote` subcommand shares: the server address and
// token flags, the gRPC channel (public API only: proto/hapticjam/v1), call
// contexts with deadlines, and gRPC status codes turned into a clear message
// and an exit code (10 + the status code, README "Remote commands").
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "args.h"

namespace hj::cli {

struct RemoteOptions {
  std::string server;   // HOST:PORT; --server or $HAPTICJAM_SERVER
  std::string token;    // bearer token; --token or $HAPTICJAM_TOKEN
  std::string ca_file;  // --tls-ca FILE: TLS with this root certificate (PEM)
  double timeout_s = 0; // --timeout S; 0 = the command's own default
};

// Flags every remote subcommand takes (--server, --token, --tls-ca, --timeout).
constexpr const char* kRemoteCommonUsage =
    "  --server HOST:PORT    the hapticjam-server (default $HAPTICJAM_SERVER)\n"
    "  --token T             bearer token (default $HAPTICJAM_TOKEN)\n"
    "  --tls-ca FILE         connect with TLS, trusting this PEM root certificate\n"
    "  --timeout S           give up after S seconds (DEADLINE_EXCEEDED)\n";

// Consumes one of the common flags at the cursor; false if it is not one.
bool take_remote_flag(ArgCursor& cursor, RemoteOptions& options);
// Fills server/token from the environment where unset; throws
// std::invalid_argument if there is still no server.
void finish_remote_options(RemoteOptions& options);

// A call failed: the server's (or gRPC's) status, for report_call_error.
class CallError : public std::runtime_error {
 public:
  CallError(std::string call, grpc::Status status)
      : std::runtime_error(call + ": " + status.error_message()), call_(std::move(call)), status_(std::move(status)) {}
  const std::string& call() const { return call_; }
  const grpc::Status& status() const { return status_; }

 private:
  std::string call_;
  grpc::Status status_;
};

// Throws CallError unless the status is OK.
void check(const grpc::Status& status, const std::string& call);

// The exit code for a failed call: 10 + the gRPC status code (13 INVALID_ARGUMENT,
// 14 DEADLINE_EXCEEDED, 17 PERMISSION_DENIED, 18 RESOURCE_EXHAUSTED,
// 19 FAILED_PRECONDITION, 24 UNAVAILABLE, 26 UNAUTHENTICATED ...).
int exit_code_for(grpc::StatusCode code);
// "INVALID_ARGUMENT", "UNAVAILABLE" ...
const char* status_code_name(grpc::StatusCode code);
// Prints "hapticjam remote NAME: CODE: message" and a hint on what to do to
// stderr; returns exit_code_for(code).
int report_call_error(const std::string& command, const CallError& error, const RemoteOptions& options);

class RemoteConnection {
 public:
  explicit RemoteConnection(const RemoteOptions& options);
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  // A context carrying the token and a deadline: --timeout if given, else
  // `default_timeout_s` (0 = none, for streams that follow a queue).
  std::unique_ptr<grpc::ClientContext> context(double default_timeout_s) const;

 private:
  RemoteOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
};

}  // namespace hj::cli

namespace hj::cli {

// run_subcommand for a remote subcommand: also turns a refused call into its
// message and exit code. Args has a `RemoteOptions remote` member.
template <class Args>
int run_remote_subcommand(const std::string& name, const char* usage, const std::vector<std::string>& args,
                          const std::function<Args(const std::vector<std::string>&)>& parse,
                          const std::function<int(const Args&)>& run) {
  const std::function<int(const Args&)> guarded = [&](const Args& parsed) {
    try {
      return run(parsed);
    } catch (const CallError& e) {
      return report_call_error(name, e, parsed.remote);
    }
  };
  return run_subcommand<Args>("remote " + name, usage, args, parse, guarded);
}

}  // namespace hj::cli
