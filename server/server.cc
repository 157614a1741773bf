#include "server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/resource_quota.h>
#include <grpcpp/server_builder.h>

#include <fstream>
#include <sstream>

#include "json_log.h"
#include "token_gate.h"

namespace hj::server {

namespace {

constexpr const char* kPlanningService = "hapticjam.v1.PlanningService";
constexpr const char* kDeviceService = "hapticjam.v1.DeviceService";
constexpr const char* kCalibrationService = "hapticjam.v1.CalibrationService";

std::string read_file(const std::string& path, const char* flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(std::string(flag) + ": cannot read \"" + path + "\"");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// With TLS and auth, the token is checked from the headers, before the
// message is parsed (token_gate.h).
std::shared_ptr<grpc::ServerCredentials> credentials(const ServerOptions& options, const Authenticator& auth) {
  if (options.tls_cert.empty()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({read_file(options.tls_key, "--tls-key"), read_file(options.tls_cert, "--tls-cert")});
  auto out = grpc::SslServerCredentials(ssl);
  if (auth.enabled()) out->SetAuthMetadataProcessor(std::make_shared<TokenGate>(auth));
  return out;
}

// The transport's bounds (ServerLimits): threads, streams per connection, keepalive.
void apply_transport_limits(const ServerLimits& limits, grpc::ServerBuilder& builder) {
  grpc::ResourceQuota quota("hapticjam-server");
  quota.SetMaxThreads(limits.max_threads);
  builder.SetResourceQuota(quota);
  builder.SetMaxReceiveMessageSize(limits.max_message_bytes);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, limits.max_concurrent_streams);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, int(limits.keepalive_time.count()));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, int(limits.keepalive_timeout.count()));
  // Clients may ping (also between calls), but no more often than every 10 s.
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 10'000);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, 2);
}

}  // namespace

HapticServer::HapticServer(ServerOptions options, std::unique_ptr<device::DeviceLink> link,
                           DeviceQueueOptions device_options)
    : options_(std::move(options)), link_(std::move(link)) {
  options_.validate();
  if (!options_.auth_file.empty()) auth_ = Authenticator::from_file(options_.auth_file);
  for (const std::string& warning : auth_.warnings()) log_event("warning", {{"message", warning}});
  for (const auto& [name, file] : options_.maps) {
    maps_.add(name, file, options_.limits);
    log_event("map_loaded", {{"name", name}, {"file", file}});
  }
  cache_ = std::make_unique<ResultCache>(options_.cache_size);
  store_ = std::make_unique<JobStore>(options_.db_file);
  device_options.max_queued = options_.device_queue_size;
  device_options.limits = options_.limits;
  device_options.prune = {options_.keep_jobs, options_.keep_days};
  queue_ = std::make_unique<DeviceQueue>(*store_, link_.get(), device_options);
  pool_ = std::make_unique<WorkPool>(options_.worker_count(), options_.queue_size);
  planning_ = std::make_unique<PlanningServiceImpl>(auth_, maps_, options_.limits, *pool_, *cache_);
  device_ = std::make_unique<DeviceServiceImpl>(auth_, *queue_, options_.limits);
  calibration_ = std::make_unique<CalibrationServiceImpl>(auth_, options_.limits, *pool_);
  render_ = std::make_unique<RenderServiceImpl>(auth_, maps_, options_.limits, *queue_);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options_.listen, credentials(options_, auth_), &port_);
  apply_transport_limits(options_.limits, builder);
  builder.RegisterService(planning_.get());
  builder.RegisterService(device_.get());
  builder.RegisterService(calibration_.get());
  builder.RegisterService(render_.get());
  server_ = builder.BuildAndStart();
  if (!server_ || port_ == 0)
    throw std::runtime_error("cannot listen on " + options_.listen + " (address in use or not valid?)");
  {
    std::lock_guard lock(health_mutex_);
    serving_ = true;
  }
  server_->GetHealthCheckService()->SetServingStatus(kPlanningService, true);
  server_->GetHealthCheckService()->SetServingStatus(kCalibrationService, true);
  queue_->start([this](bool serving) { set_device_health(serving); });
  log_event("server_started", {{"listen", options_.listen},
                               {"port", port_},
                               {"workers", pool_->workers()},
                               {"queue_size", options_.queue_size},
                               {"auth", auth_.enabled()},
                               {"tls", !options_.tls_cert.empty()},
                               {"db", options_.db_file},
                               {"device", options_.device}});
}

HapticServer::~HapticServer() { shutdown(); }

void HapticServer::set_device_health(bool serving) {
  std::lock_guard lock(health_mutex_);
  if (serving_) server_->GetHealthCheckService()->SetServingStatus(kDeviceService, serving);
}

void HapticServer::shutdown() {
  std::lock_guard lock(shutdown_mutex_);
  if (shut_down_) return;
  shut_down_ = true;
  log_event("server_stopping");
  {
    std::lock_guard health(health_mutex_);
    serving_ = false;
  }
  // The queue first (its watchers end, the link stops calling back), then
  // the calls in flight get a moment before they are cancelled.
  queue_->stop();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  log_event("server_stopped");
}

void HapticServer::wait() { server_->Wait(); }

}  // namespace hj::server
