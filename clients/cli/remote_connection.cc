#include "remote_connection.h"

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

namespace hj::cli {

namespace {

// Goals (meshes, DEMs) and results may exceed gRPC's 4 MiB default; the server
// accepts up to --max-message-mib (64 MiB by default).
constexpr int kMaxMessageBytes = 64 << 20;

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument("--tls-ca: cannot read \"" + path + "\"");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

bool take_remote_flag(ArgCursor& cursor, RemoteOptions& options) {
  const std::string& a = cursor.arg();
  if (a == "--server") options.server = cursor.value();
  else if (a == "--token") options.token = cursor.value();
  else if (a == "--tls-ca") options.ca_file = cursor.value();
  else if (a == "--timeout") {
    options.timeout_s = parse_number(a, cursor.value());
    if (!(options.timeout_s > 0.0)) throw std::invalid_argument("--timeout needs a positive number of seconds");
  } else return false;
  return true;
}

void finish_remote_options(RemoteOptions& options) {
  if (options.server.empty())
    if (const char* env = std::getenv("HAPTICJAM_SERVER")) options.server = env;
  if (options.token.empty())
    if (const char* env = std::getenv("HAPTICJAM_TOKEN")) options.token = env;
  if (options.server.empty()) throw std::invalid_argument("missing --server HOST:PORT (or $HAPTICJAM_SERVER)");
  if (options.server.find(':') == std::string::npos)
    throw std::invalid_argument("--server needs HOST:PORT, got \"" + options.server + "\"");
}

void check(const grpc::Status& status, const std::string& call) {
  if (!status.ok()) throw CallError(call, status);
}

int exit_code_for(grpc::StatusCode code) { return 10 + static_cast<int>(code); }

const char* status_code_name(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN";
  }
}

int report_call_error(const std::string& command, const CallError& error, const RemoteOptions& options) {
  const grpc::StatusCode code = error.status().error_code();
  std::string hint;
  switch (code) {
    case grpc::StatusCode::UNAVAILABLE: hint = "is hapticjam-server running at " + options.server + "?"; break;
    case grpc::StatusCode::UNAUTHENTICATED: hint = "the server does not know this token: check --token"; break;
    case grpc::StatusCode::PERMISSION_DENIED: hint = "this token's role does not allow it"; break;
    case grpc::StatusCode::RESOURCE_EXHAUSTED: hint = "the server is busy: try again later"; break;
    case grpc::StatusCode::DEADLINE_EXCEEDED: hint = "no answer in time: raise --timeout"; break;
    case grpc::StatusCode::FAILED_PRECONDITION: hint = "see 'hapticjam remote status'"; break;
    default: break;
  }
  std::cerr << "hapticjam remote " << command << ": " << status_code_name(code) << ": " << error.call() << ": "
            << error.status().error_message() << (hint.empty() ? "" : " (" + hint + ")") << "\n";
  return exit_code_for(code);
}

RemoteConnection::RemoteConnection(const RemoteOptions& options) : options_(options) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(kMaxMessageBytes);
  args.SetMaxSendMessageSize(kMaxMessageBytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (options.ca_file.empty()) {
    credentials = grpc::InsecureChannelCredentials();
  } else {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = read_text_file(options.ca_file);
    credentials = grpc::SslCredentials(ssl);
  }
  channel_ = grpc::CreateCustomChannel(options.server, credentials, args);
}

std::unique_ptr<grpc::ClientContext> RemoteConnection::context(double default_timeout_s) const {
  auto context = std::make_unique<grpc::ClientContext>();
  const double timeout = options_.timeout_s > 0 ? options_.timeout_s : default_timeout_s;
  if (timeout > 0)
    context->set_deadline(std::chrono::system_clock::now() +
                          std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(timeout)));
  if (!options_.token.empty()) context->AddMetadata("authorization", "Bearer " + options_.token);
  return context;
}

}  // namespace hj::cli
