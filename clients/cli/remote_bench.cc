// remote bench: Preview calls per second and latency percentiles for 1, 4,
// 16 ... concurrent clients (one channel each, every request a new goal so
// the cache never answers), then the time a cached repeat takes.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "hapticjam/v1/planning_service.grpc.pb.h"
#include "remote_command.h"
#include "remote_connection.h"

namespace hj::cli {

namespace v1 = ::hapticjam::v1;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kBenchUsage =
    "usage: hapticjam remote bench --server HOST:PORT [--rows 6 --cols 8] [--clients 1,4,16]\n"
    "                              [--seconds S] [--goal FILE] [--json]\n"
    "Measures Preview on the server: for each number of concurrent clients (each on its\n"
    "own connection, each request a different goal so none is cached) the calls per\n"
    "second, p50 and p99 latency and refusals by status code; then the latency of a\n"
    "repeated (cached) request.\n"
    "  --rows R --cols C   array (default 6 x 8)\n"
    "  --clients LIST      concurrency levels (default 1,4,16)\n"
    "  --seconds S         time per level (default 5)\n"
    "  --goal FILE         plan this goal (each request a slightly different region);\n"
    "                      default: a synthetic bump, moved for every request\n"
    "  --json              one JSON object per level\n";

struct BenchArgs {
  RemoteOptions remote;
  int rows = 6, cols = 8;
  std::vector<int> clients = {1, 4, 16};
  double seconds = 5.0;
  bool json = false;
  std::string goal_file;
  std::string goal_bytes;  // read once
};

BenchArgs parse_bench(const std::vector<std::string>& args) {
  BenchArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote)) continue;
    if (a == "--rows") out.rows = parse_int(a, c.value(), 1, 64);
    else if (a == "--cols") out.cols = parse_int(a, c.value(), 1, 64);
    else if (a == "--seconds") {
      out.seconds = parse_number(a, c.value());
      if (!(out.seconds > 0)) throw std::invalid_argument("--seconds needs a positive number");
    } else if (a == "--json") out.json = true;
    else if (a == "--goal") out.goal_file = c.value();
    else if (a == "--clients") {
      out.clients.clear();
      std::stringstream in(c.value());
      for (std::string n; std::getline(in, n, ',');) out.clients.push_back(parse_int(a, n, 1, 1024));
    } else throw std::invalid_argument("unexpected argument \"" + a + "\"");
  }
  finish_remote_options(out.remote);
  if (!out.goal_file.empty()) {
    std::ifstream in(out.goal_file, std::ios::binary);
    if (!in) throw std::invalid_argument("--goal: cannot read \"" + out.goal_file + "\"");
    std::ostringstream bytes;
    bytes << in.rdbuf();
    out.goal_bytes = bytes.str();
  }
  return out;
}

// A smooth bump (a 24 x 32 height table) placed by `k`: a different goal for every k.
std::string bump_csv(long k) {
  const double ci = 6 + (k % 13), cj = 8 + (k / 13 % 17);
  std::ostringstream s;
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 32; ++j)
      s << (j ? "," : "") << 100.0 * std::exp(-((i - ci) * (i - ci) + (j - cj) * (j - cj)) / 40.0) + 1e-6 * double(k);
    s << "\n";
  }
  return s.str();
}

v1::PreviewRequest preview_request(const BenchArgs& args, long k) {
  v1::PreviewRequest r;
  r.mutable_array()->set_rows(args.rows);
  r.mutable_array()->set_cols(args.cols);
  if (args.goal_file.empty()) {
    r.mutable_goal()->mutable_file()->set_content(bump_csv(k));
    r.mutable_goal()->mutable_file()->set_file_name("bump.csv");
    return r;
  }
  // The whole goal but for a sliver of 1e-6 k of its width: a new request, the same work.
  r.mutable_goal()->mutable_file()->set_content(args.goal_bytes);
  r.mutable_goal()->mutable_file()->set_file_name(std::filesystem::path(args.goal_file).filename().string());
  v1::Region* region = r.mutable_goal()->mutable_region();
  region->set_x0(1e-6 * double(k % 100'000)), region->set_y0(0), region->set_x1(1), region->set_y1(1);
  return r;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

std::unique_ptr<v1::PlanningService::Stub> own_stub(const RemoteOptions& remote, int client) {
  // A distinct channel argument gives each client its own connection.
  grpc::ChannelArguments channel_args;
  channel_args.SetInt("hapticjam.bench_client", client);
  return v1::PlanningService::NewStub(
      grpc::CreateCustomChannel(remote.server, grpc::InsecureChannelCredentials(), channel_args));
}

std::unique_ptr<grpc::ClientContext> bench_context(const RemoteOptions& remote) {
  auto c = std::make_unique<grpc::ClientContext>();
  c->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(900));
  if (!remote.token.empty()) c->AddMetadata("authorization", "Bearer " + remote.token);
  return c;
}

int bench(const BenchArgs& args) {
  std::atomic<long> next_goal{std::chrono::system_clock::now().time_since_epoch().count() % 1'000'000};
  for (const int clients : args.clients) {
    std::mutex mutex;
    std::vector<double> latencies_ms;
    std::map<std::string, int> refused;
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration<double>(args.seconds);
    std::vector<std::thread> threads;
    for (int t = 0; t < clients; ++t)
      threads.emplace_back([&, t] {
        auto stub = own_stub(args.remote, t);
        while (Clock::now() < end) {
          const v1::PreviewRequest request = preview_request(args, next_goal++);
          v1::PreviewResponse response;
          const auto t0 = Clock::now();
          const grpc::Status status = stub->Preview(bench_context(args.remote).get(), request, &response);
          const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
          std::lock_guard lock(mutex);
          if (status.ok()) latencies_ms.push_back(ms);
          else ++refused[status_code_name(status.error_code())];
        }
      });
    for (auto& t : threads) t.join();
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    const double rate = double(latencies_ms.size()) / wall;
    nlohmann::json refusals = refused;
    if (args.json) {
      std::printf("%s\n", nlohmann::json({{"clients", clients}, {"calls", latencies_ms.size()}, {"seconds", wall},
                                          {"calls_per_second", rate}, {"p50_ms", percentile(latencies_ms, 0.5)},
                                          {"p99_ms", percentile(latencies_ms, 0.99)}, {"refused", refusals}})
                              .dump()
                              .c_str());
    } else {
      std::printf("%2d client(s), %d x %d: %zu previews in %.1f s = %.2f/s, p50 %.0f ms, p99 %.0f ms%s%s\n", clients,
                  args.rows, args.cols, latencies_ms.size(), wall, rate, percentile(latencies_ms, 0.5),
                  percentile(latencies_ms, 0.99), refused.empty() ? "" : ", refused ", refused.empty() ? "" : refusals.dump().c_str());
    }
    std::fflush(stdout);
  }

  // A repeated request: the first computes, the repeats come from the cache.
  auto stub = own_stub(args.remote, -1);
  const v1::PreviewRequest request = preview_request(args, next_goal++);
  v1::PreviewResponse response;
  check(stub->Preview(bench_context(args.remote).get(), request, &response), "Preview");
  std::vector<double> cached_ms;
  int cached = 0;
  for (int i = 0; i < 50; ++i) {
    const auto t0 = Clock::now();
    check(stub->Preview(bench_context(args.remote).get(), request, &response), "Preview");
    cached_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    cached += response.cached();
  }
  if (args.json)
    std::printf("%s\n", nlohmann::json({{"cached_repeats", cached_ms.size()}, {"answered_from_cache", cached},
                                        {"p50_ms", percentile(cached_ms, 0.5)}, {"p99_ms", percentile(cached_ms, 0.99)}})
                            .dump()
                            .c_str());
  else
    std::printf("cached repeat: %d/%zu answered from the cache, p50 %.2f ms, p99 %.2f ms\n", cached, cached_ms.size(),
                percentile(cached_ms, 0.5), percentile(cached_ms, 0.99));
  return 0;
}

}  // namespace

int run_remote_bench(const std::vector<std::string>& args) {
  static const std::string usage = std::string(kBenchUsage) + kRemoteCommonUsage;
  return run_remote_subcommand<BenchArgs>("bench", usage.c_str(), args, parse_bench, bench);
}

}  // namespace hj::cli
