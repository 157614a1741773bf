// Server speed: Preview calls per second and their p50 / p99 latency for 1, 4
// and 16 concurrent clients on a 6 x 8 array (Preview's coarse mesh, 2
// segments) with 1 and 2 planning workers, cache off; and the time of a
// request answered from the cache. Run:
//   ./build/hj_bench --benchmark_filter=Server
#include <benchmark/benchmark.h>
#include <grpcpp/create_channel.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "hapticjam/v1/planning_service.grpc.pb.h"
#include "json_log.h"
#include "server.h"

namespace {

namespace v1 = ::hapticjam::v1;
using Clock = std::chrono::steady_clock;

std::unique_ptr<hj::server::HapticServer> start_server(int workers, int cache_size, const std::string& db) {
  hj::server::set_logging_enabled(false);
  hj::server::ServerOptions o;
  o.listen = "127.0.0.1:0";
  o.workers = workers;
  o.queue_size = 64;
  o.cache_size = cache_size;
  o.db_file = db;
  o.maps = {{"volcano", HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv"}};
  return std::make_unique<hj::server::HapticServer>(o, nullptr);
}

// The i-th region of a zoom over the volcano, on a 6 x 8 array.
v1::PreviewRequest zoom_request(int i) {
  v1::PreviewRequest r;
  r.mutable_array()->set_rows(6);
  r.mutable_array()->set_cols(8);
  r.mutable_goal()->set_map_name("volcano");
  auto* region = r.mutable_goal()->mutable_region();
  const double shift = 0.02 * (i % 10);
  region->set_x0(shift), region->set_y0(shift), region->set_x1(0.7 + shift), region->set_y1(0.7 + shift);
  return r;
}

std::string db_path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("hj_bench_") + name + ".db")).string();
}

// state.range(0) workers, state.range(1) clients, each making `calls` calls.
void BM_ServerPreview(benchmark::State& state) {
  const int workers = int(state.range(0)), clients = int(state.range(1));
  const int calls = clients == 1 ? 4 : 2;
  const std::string db = db_path("preview");
  std::filesystem::remove(db);
  auto server = start_server(workers, 0, db);
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server->port()), grpc::InsecureChannelCredentials());
  std::vector<double> latencies_ms;
  std::mutex mutex;
  std::atomic<int> failures{0};
  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = Clock::now();
    std::vector<std::thread> threads;
    for (int c = 0; c < clients; ++c)
      threads.emplace_back([&, c] {
        auto stub = v1::PlanningService::NewStub(channel);
        for (int k = 0; k < calls; ++k) {
          grpc::ClientContext context;
          v1::PreviewResponse response;
          const auto t0 = Clock::now();
          if (!stub->Preview(&context, zoom_request(c * calls + k), &response).ok()) ++failures;
          const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
          std::lock_guard lock(mutex);
          latencies_ms.push_back(ms);
        }
      });
    for (auto& t : threads) t.join();
    seconds += std::chrono::duration<double>(Clock::now() - start).count();
  }
  std::sort(latencies_ms.begin(), latencies_ms.end());
  auto percentile = [&](double p) { return latencies_ms[size_t(std::min<double>(latencies_ms.size() - 1, p * latencies_ms.size()))]; };
  state.counters["calls_per_s"] = double(latencies_ms.size()) / seconds;
  state.counters["p50_ms"] = percentile(0.50);
  state.counters["p99_ms"] = percentile(0.99);
  state.counters["calls"] = double(latencies_ms.size());
  state.counters["failures"] = failures.load();
  server->shutdown();
  std::filesystem::remove(db);
}

BENCHMARK(BM_ServerPreview)
    ->ArgNames({"workers", "clients"})
    ->ArgsProduct({{1, 2}, {1, 4, 16}})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// A zoom back to a region already planned: answered from the cache.
void BM_ServerCachedPreview(benchmark::State& state) {
  const std::string db = db_path("cached");
  std::filesystem::remove(db);
  auto server = start_server(1, 16, db);
  auto stub = v1::PlanningService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server->port()), grpc::InsecureChannelCredentials()));
  const v1::PreviewRequest request = zoom_request(3);
  {
    grpc::ClientContext context;
    v1::PreviewResponse warm;
    stub->Preview(&context, request, &warm);
  }
  for (auto _ : state) {
    grpc::ClientContext context;
    v1::PreviewResponse response;
    stub->Preview(&context, request, &response);
    if (!response.cached()) state.SkipWithError("not answered from the cache");
  }
  server->shutdown();
  std::filesystem::remove(db);
}

BENCHMARK(BM_ServerCachedPreview)->Unit(benchmark::kMicrosecond);

}  // namespace
