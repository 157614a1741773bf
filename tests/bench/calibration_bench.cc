// The calibration RPCs' own cost beside the library's: turning an uploaded
// dataset into a Dataset (scratch files, then read_dataset) against reading
// the same folder from disk, and a whole Compare over loopback against the
// library's evaluate_dataset on the same data (demo-baseline, 6 sessions,
// 38 captures, about 0.5 MB uploaded). Run:
//   ./build/hj_bench --benchmark_filter=Calibration
#include <benchmark/benchmark.h>
#include <grpcpp/create_channel.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "calib/residuals.h"
#include "dataset_upload.h"
#include "hapticjam/v1/calibration_service.grpc.pb.h"
#include "json_log.h"
#include "server.h"

namespace {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";
constexpr int kSegments = 2;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

v1::UploadedDataset upload(const fs::path& dir) {
  v1::UploadedDataset out;
  out.set_name(dir.filename().string());
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!fs::exists(e.path() / "session.json")) continue;
    v1::UploadedSession* s = out.add_sessions();
    s->set_name(e.path().filename().string());
    s->set_session_json(read(e.path() / "session.json"));
    for (const auto& f : fs::recursive_directory_iterator(e.path() / "frames")) {
      v1::SessionFile* file = s->add_files();
      file->set_path(fs::relative(f.path(), e.path()).generic_string());
      file->set_content(read(f.path()));
    }
  }
  return out;
}

void BM_CalibrationDatasetFromUpload(benchmark::State& state) {
  const v1::UploadedDataset u = upload(kBaseline);
  for (auto _ : state) benchmark::DoNotOptimize(hj::server::dataset_from_upload(u, hj::server::ServerLimits{}));
  state.counters["bytes"] = static_cast<double>(u.ByteSizeLong());
}
BENCHMARK(BM_CalibrationDatasetFromUpload)->Unit(benchmark::kMillisecond);

void BM_CalibrationReadDatasetFromDisk(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(hj::read_dataset(kBaseline));
}
BENCHMARK(BM_CalibrationReadDatasetFromDisk)->Unit(benchmark::kMillisecond);

hj::ModelParams paper_model(const hj::Dataset& d) {
  hj::ModelParams p;
  p.surface = hj::SurfaceParameters::paper_defaults(d.device().geometry(kSegments));
  p.surface.max_pressure_pa = d.device().max_pressure_kpa * 1000.0;
  return p;
}

// A whole Compare: upload, conversion, replays on a worker, the stream back.
void BM_CalibrationCompareRpc(benchmark::State& state) {
  hj::server::set_logging_enabled(false);
  hj::server::ServerOptions o;
  o.listen = "127.0.0.1:0";
  o.workers = 1;
  o.db_file = (fs::temp_directory_path() / "hj_bench_calibration.db").string();
  fs::remove(o.db_file);
  hj::server::HapticServer server(o, nullptr);
  auto stub = v1::CalibrationService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(server.port()), grpc::InsecureChannelCredentials()));
  v1::CompareRequest request;
  *request.mutable_dataset() = upload(kBaseline);
  request.mutable_options()->set_segments(kSegments);
  for (auto _ : state) {
    grpc::ClientContext context;
    auto reader = stub->Compare(&context, request);
    v1::CompareEvent event;
    while (reader->Read(&event)) {
    }
    if (!reader->Finish().ok()) state.SkipWithError("Compare failed");
  }
}
BENCHMARK(BM_CalibrationCompareRpc)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The library's part of it.
void BM_CalibrationCompareLibrary(benchmark::State& state) {
  const hj::Dataset d = hj::read_dataset(kBaseline);
  hj::ReplayOptions replay;
  replay.segments = kSegments;
  for (auto _ : state) benchmark::DoNotOptimize(hj::evaluate_dataset(d, paper_model(d), replay));
}
BENCHMARK(BM_CalibrationCompareLibrary)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
