// The whole server in one object: gRPC services (planning, device,
// calibration, health, reflection) over the work pool, result cache, job store and device queue.
// main.cc only parses flags, opens the device link and waits for a signal;
// tests start one in-process on a loopback port 0.
#pragma once

#include <grpcpp/server.h>

#include <memory>
#include <mutex>

#include "auth.h"
#include "calibration_service.h"
#include "device/device_link.h"
#include "device_queue.h"
#include "device_service.h"
#include "goal_source.h"
#include "job_store.h"
#include "planning_service.h"
#include "render_service.h"
#include "result_cache.h"
#include "server_options.h"
#include "work_pool.h"

namespace hj::server {

class HapticServer {
 public:
  // Reads the auth file and maps, opens the database, starts the link (may be
  // null: no device) and listens.
  // @throws std::invalid_argument (bad options, auth file, map) or
  //         std::runtime_error (database, cannot listen), naming the cause.
  HapticServer(ServerOptions options, std::unique_ptr<device::DeviceLink> link,
               DeviceQueueOptions device_options = {});
  ~HapticServer();
  HapticServer(const HapticServer&) = delete;
  HapticServer& operator=(const HapticServer&) = delete;

  int port() const { return port_; }
  // Stops accepting calls, cancels running ones after a short grace time,
  // stops the device queue and the link. Idempotent, thread-safe.
  void shutdown();
  // Blocks until shutdown() has finished.
  void wait();

  // For tests and benchmarks.
  WorkPool& pool() { return *pool_; }
  ResultCache& cache() { return *cache_; }

 private:
  void set_device_health(bool serving);

  ServerOptions options_;
  Authenticator auth_;
  MapStore maps_;
  std::unique_ptr<ResultCache> cache_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<device::DeviceLink> link_;
  std::unique_ptr<DeviceQueue> queue_;
  std::unique_ptr<WorkPool> pool_;
  std::unique_ptr<PlanningServiceImpl> planning_;
  std::unique_ptr<DeviceServiceImpl> device_;
  std::unique_ptr<CalibrationServiceImpl> calibration_;
  std::unique_ptr<RenderServiceImpl> render_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;

  std::mutex health_mutex_;
  bool serving_ = false;
  std::mutex shutdown_mutex_;
  bool shut_down_ = false;
};

}  // namespace hj::server
