// CalibrationService over gRPC against an in-process server, on a tiny
// synthetic dataset (3 x 4 array, two short sessions, a coarse mesh): the
// streamed compare, fit and diagnosis (with its report.html) equal the
// library's own on the same data, progress comes before the result and does
// not go back within a stage, a malformed upload is refused naming the file
// and key, cancelling or a passed deadline (the caller's or the server's
// --max-calibration-seconds) frees the worker of a fit or diagnosis that
// would take minutes, and a previewer may compare but not fit.
#include <gtest/gtest.h>

#include <fstream>

#include "calib/calibration_json.h"
#include "calib/report/compare_report.h"
#include "calib/report/diagnose_report_html.h"
#include "calib/report/fit_report_html.h"
#include "calib/diagnosis.h"
#include "calib/fit_model.h"
#include "calib/synthesize.h"
#include "hapticjam/v1/calibration_service.grpc.pb.h"
#include "server_fixture.h"

namespace hj {
namespace {

using namespace testing_support;
using grpc::StatusCode;
namespace fs = std::filesystem;

constexpr int kSegments = 2;  // coarse, for speed; the request asks for the same
const fs::path kBending = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-bending";

std::string session_json(const std::string& name, const std::string& steps) {
  return R"({"format": "hapticjam.session/1", "name": ")" + name +
         R"(", "device": {"rows": 3, "cols": 4, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
  "sensor": {"kind": "depth camera", "resolution_mm": 1.0, "accuracy_mm": 1.0},
  "grid": {"nx": 20, "ny": 15, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 8.0, "dy_mm": 8.0},
  "steps": [)" + steps + "]}";
}

// Two short sessions (a pressure sweep; a jammed cell) seen through a
// simulated camera, made once for all tests of this file.
class CalibrationService : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::path(::testing::TempDir()) / ("hj_calibration_service_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    const fs::path plan = root_ / "plan";
    fs::create_directories(plan / "sweep");
    fs::create_directories(plan / "jammed");
    std::ofstream(plan / "sweep" / "session.json") << session_json(
        "sweep", R"({"op": "capture", "frame": "frames/000.csv", "label": "rest"},
                    {"op": "set_pressure", "kpa": 0.6}, {"op": "capture", "frame": "frames/001.csv"},
                    {"op": "set_pressure", "kpa": 1.2}, {"op": "capture", "frame": "frames/002.csv"})");
    std::ofstream(plan / "jammed" / "session.json") << session_json(
        "jammed", R"({"op": "set_pressure", "kpa": 1.0}, {"op": "jam", "cell": [1, 1]},
                     {"op": "capture", "frame": "frames/000.csv"},
                     {"op": "set_pressure", "kpa": 0.5}, {"op": "capture", "frame": "frames/001.csv"})");
    synthesize_dataset(plan, root_ / "tiny", truth(), synth_options());
  }
  // The paper's model with a heavier membrane and softer springs, so that a
  // fit from the paper's values has somewhere to go.
  static ModelParams truth() {
    ModelParams truth;
    truth.surface = SurfaceParameters::paper_defaults(ArrayGeometry{3, 4, 0.038, kSegments});
    truth.surface.mass_kg *= 1.25;
    truth.surface.spring_k *= 0.8;
    return truth;
  }
  static SynthOptions synth_options() {
    SynthOptions synth;
    synth.segments = kSegments;
    return synth;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }
  static fs::path dataset_dir() { return root_ / "tiny"; }

  static fs::path root_;
};
fs::path CalibrationService::root_;

// A dataset folder as the client uploads it: session.json and the frames.
v1::UploadedDataset upload(const fs::path& dir) {
  auto read = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  v1::UploadedDataset out;
  out.set_name(dir.filename().string());
  std::vector<fs::path> sessions;
  for (const auto& e : fs::directory_iterator(dir))
    if (fs::exists(e.path() / "session.json")) sessions.push_back(e.path());
  std::sort(sessions.begin(), sessions.end());
  for (const auto& s : sessions) {
    v1::UploadedSession* u = out.add_sessions();
    u->set_name(s.filename().string());
    u->set_session_json(read(s / "session.json"));
    for (const auto& f : fs::recursive_directory_iterator(s / "frames")) {
      v1::SessionFile* file = u->add_files();
      file->set_path(fs::relative(f.path(), s).generic_string());
      file->set_content(read(f.path()));
    }
  }
  return out;
}

server::ServerOptions options(int workers, int queue_size, const fs::path& db) {
  server::ServerOptions o;
  o.workers = workers;
  o.queue_size = queue_size;
  o.db_file = db.string();
  return o;
}

struct Client {
  explicit Client(TestServer& s) : stub(v1::CalibrationService::NewStub(s.channel)) {}
  std::unique_ptr<v1::CalibrationService::Stub> stub;
};

// Every event of a call, and how it ended.
template <class Event>
struct Stream {
  std::vector<Event> events;
  grpc::Status status;
};

template <class Event>
Stream<Event> read_all(grpc::ClientReader<Event>& reader) {
  Stream<Event> out;
  for (Event e; reader.Read(&e);) out.events.push_back(e);
  out.status = reader.Finish();
  return out;
}

// Progress events first, then exactly one result; within a stage `done`
// does not decrease and stays within `total`. Returns the stages seen.
template <class Event>
std::vector<std::string> expect_progress_then_result(const std::vector<Event>& events) {
  std::vector<std::string> stages;
  EXPECT_GE(events.size(), 2u);
  for (size_t k = 0; k + 1 < events.size(); ++k) {
    EXPECT_TRUE(events[k].has_progress()) << "event " << k << " before the last is not progress";
    const v1::CalibrationProgress& p = events[k].progress();
    EXPECT_LE(p.done(), p.total()) << p.stage();
    if (stages.empty() || stages.back() != p.stage()) stages.push_back(p.stage());
    else EXPECT_GE(p.done(), events[k - 1].progress().done()) << p.stage() << " went back";
  }
  EXPECT_TRUE(!events.empty() && events.back().has_result());
  return stages;
}

ModelParams paper_start(const Dataset& dataset) {
  ModelParams p;
  p.surface = SurfaceParameters::paper_defaults(dataset.device().geometry(kSegments));
  p.surface.max_pressure_pa = dataset.device().max_pressure_kpa * 1000.0;
  return p;
}

v1::CompareRequest compare_request(const fs::path& dir) {
  v1::CompareRequest r;
  *r.mutable_dataset() = upload(dir);
  r.mutable_options()->set_segments(kSegments);
  return r;
}

TEST_F(CalibrationService, CompareStreamsTheLibrarysComparison) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  Client c(s);
  auto context = call();
  auto reader = c.stub->Compare(context.get(), compare_request(dataset_dir()));
  const auto stream = read_all(*reader);
  ASSERT_TRUE(stream.status.ok()) << stream.status.error_message();
  const auto stages = expect_progress_then_result(stream.events);
  EXPECT_EQ(stages, (std::vector<std::string>{"compare", "heat maps"}));
  const v1::CompareResult& r = stream.events.back().result();

  const Dataset dataset = read_dataset(dataset_dir());
  ReplayOptions replay;
  replay.segments = kSegments;
  const ModelParams params = paper_start(dataset);
  const Evaluation local = evaluate_dataset(dataset, params, replay);
  EXPECT_NEAR(r.rmse_mm(), local.rmse_mm(), 1e-9);
  EXPECT_GT(r.rmse_mm(), 2.0 * r.noise_floor_mm());  // the paper's model is not the truth
  EXPECT_NEAR(r.mae_mm(), local.mae_mm(), 1e-9);
  EXPECT_EQ(r.samples(), local.samples);
  EXPECT_NEAR(r.noise_floor_mm(), noise_floor_mm(dataset), 1e-12);
  // The same summary.json, report.html and heat maps as `hapticjam compare`
  // writes (NaN as null in both).
  const CompareReport report = compare_report(dataset, params, local, 5.0);
  EXPECT_EQ(nlohmann::json::parse(r.summary_json()), nlohmann::json::parse(report.summary.dump()));
  EXPECT_EQ(r.report_html(), report.html);
  ASSERT_EQ(r.maps_size(), static_cast<int>(report.maps.size()));
  ASSERT_EQ(r.maps_size(), dataset.capture_count());
  for (int i = 0; i < r.maps_size(); ++i) {
    EXPECT_EQ(r.maps(i).path(), report.maps[i].path);
    EXPECT_TRUE(r.maps(i).content() == report.maps[i].bytes) << r.maps(i).path();
  }
}

TEST_F(CalibrationService, FitReturnsTheLibrarysParameters) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  Client c(s);
  v1::FitRequest request;
  *request.mutable_dataset() = upload(dataset_dir());
  request.mutable_options()->set_segments(kSegments);
  request.mutable_options()->set_max_iterations(2);
  request.mutable_options()->set_threads(1);  // many short replays: threads cost more than they give
  request.set_no_initial(true);
  auto context = call();
  auto reader = c.stub->Fit(context.get(), request);
  const auto stream = read_all(*reader);
  ASSERT_TRUE(stream.status.ok()) << stream.status.error_message();
  const auto stages = expect_progress_then_result(stream.events);
  EXPECT_NE(std::find(stages.begin(), stages.end(), "least squares"), stages.end());
  bool rmse_reported = false;
  for (const auto& e : stream.events)
    if (e.has_progress() && e.progress().stage() == "least squares") rmse_reported |= e.progress().has_rmse_mm();
  EXPECT_TRUE(rmse_reported) << "least-squares progress carries the current RMSE";
  const v1::FitResult& r = stream.events.back().result();

  const Dataset dataset = read_dataset(dataset_dir());
  FitOptions fit;
  fit.initial_estimates = false;
  fit.least_squares.max_iterations = 2;
  fit.least_squares.replay.segments = kSegments;
  fit.least_squares.replay.threads = 1;
  fit.least_squares.replay = fitting_replay(fit.least_squares.replay);
  fit.bisection.replay = fit.least_squares.replay;
  fit.profile_loose = true;
  const FitReport local = fit_model(dataset, paper_start(dataset), {}, fit);
  EXPECT_NEAR(r.rmse_mm(), local.joint.rmse_mm, 1e-9);
  ASSERT_EQ(r.parameters_size(), static_cast<int>(local.joint.estimates.size()));
  for (int k = 0; k < r.parameters_size(); ++k) {
    const ParameterEstimate& e = local.joint.estimates[k];
    const v1::FittedParameter& p = r.parameters(k);
    EXPECT_EQ(p.name(), e.parameter.qualified_name());
    EXPECT_NEAR(p.value(), e.value, 1e-9 * std::max(1.0, std::abs(e.value))) << p.name();
    EXPECT_EQ(p.active(), e.active) << p.name();
    if (e.active) {
      EXPECT_NEAR(p.ci95_low(), e.ci95_low, 1e-9 * std::max(1.0, std::abs(e.ci95_low))) << p.name();
      EXPECT_NEAR(p.ci95_high(), e.ci95_high, 1e-9 * std::max(1.0, std::abs(e.ci95_high))) << p.name();
    }
  }
  // From the paper's values to the truth's (the fit has a use).
  auto fitted = [&](const std::string& name) {
    for (const auto& p : r.parameters())
      if (p.name() == name) return p.value();
    ADD_FAILURE() << "no parameter " << name;
    return 0.0;
  };
  // report.html as `hapticjam fit` writes it.
  EXPECT_EQ(r.report_html(), fit_report_html(dataset_dir().filename().string(), local,
                                              {{"sessions", nlohmann::json::array()}}));
  EXPECT_NEAR(fitted("mass_kg"), truth().surface.mass_kg, 0.03 * truth().surface.mass_kg);
  EXPECT_NEAR(fitted("spring_k"), truth().surface.spring_k, 0.03 * truth().surface.spring_k);
  EXPECT_LT(r.rmse_mm(), 1.1 * r.noise_floor_mm());
  // params.json loads as `--params` does, to the fitted values.
  const ModelParams loaded = parse_model_params(nlohmann::json::parse(r.params_json()), SurfaceParameters{}, "params");
  EXPECT_NEAR(loaded.surface.mass_kg, local.joint.params.surface.mass_kg, 1e-12);
  EXPECT_NEAR(loaded.surface.spring_k, local.joint.params.surface.spring_k, 1e-9);
  EXPECT_EQ(nlohmann::json::parse(r.params_json())["dataset"], "tiny");
}

// One cheap candidate on the tiny dataset (its truth needs no effect): the
// verdict and figures of the library's diagnosis, and report.html as
// `hapticjam diagnose` builds it from the same diagnosis (with the run time
// the server measured and no CPU time).
TEST_F(CalibrationService, DiagnoseReturnsTheLibrarysDiagnosisAndItsPage) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  Client c(s);
  v1::DiagnoseRequest request;
  *request.mutable_dataset() = upload(dataset_dir());
  request.mutable_options()->set_segments(kSegments);
  request.mutable_options()->set_max_iterations(2);
  request.mutable_options()->set_threads(1);
  request.mutable_options()->add_effects("pressure_offset");
  auto context = call();
  auto reader = c.stub->Diagnose(context.get(), request);
  const auto stream = read_all(*reader);
  ASSERT_TRUE(stream.status.ok()) << stream.status.error_message();
  expect_progress_then_result(stream.events);
  const v1::DiagnoseResult& r = stream.events.back().result();

  const Dataset dataset = read_dataset(dataset_dir());
  DiagnoseOptions diagnose_options;
  diagnose_options.candidates = {"pressure_offset"};
  diagnose_options.fit.least_squares.max_iterations = 2;
  diagnose_options.fit.least_squares.replay.segments = kSegments;
  diagnose_options.fit.least_squares.replay.threads = 1;
  diagnose_options.fit.least_squares.replay = fitting_replay(diagnose_options.fit.least_squares.replay);
  diagnose_options.fit.bisection.replay = diagnose_options.fit.least_squares.replay;
  const Diagnosis local = diagnose(dataset, paper_start(dataset), diagnose_options);
  EXPECT_EQ(std::vector<std::string>(r.verdict().begin(), r.verdict().end()), local.verdict);
  EXPECT_NEAR(r.baseline_rmse_mm(), local.baseline.joint.rmse_mm, 1e-9);
  EXPECT_NEAR(r.baseline_heldout_rmse_mm(), local.baseline_heldout_rmse_mm, 1e-9);
  ASSERT_EQ(local.ranking.size(), 1u);
  EXPECT_EQ(r.report_html(),
            diagnose_report_html("tiny", local, diagnose_options, DiagnoseRunTime{r.seconds(), std::nullopt}));
  EXPECT_NE(r.report_html().find("<h2>Error ladder</h2>\n<svg"), std::string::npos);
  EXPECT_NE(r.report_html().find("<tr><td>pressure_offset</td>"), std::string::npos);
}

TEST_F(CalibrationService, AMalformedUploadIsRefusedNamingTheFileAndKey) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  Client c(s);
  auto refused = [&](const v1::CompareRequest& request) {
    auto context = call();
    auto reader = c.stub->Compare(context.get(), request);
    return read_all(*reader).status;
  };
  auto expect_refused = [&](const v1::CompareRequest& request, std::vector<std::string> parts) {
    const grpc::Status status = refused(request);
    EXPECT_EQ(status.error_code(), StatusCode::INVALID_ARGUMENT) << status.error_message();
    for (const auto& part : parts) EXPECT_NE(status.error_message().find(part), std::string::npos)
        << "\"" << status.error_message() << "\" lacks \"" << part << "\"";
    EXPECT_EQ(status.error_message().find(::testing::TempDir()), std::string::npos) << "names a server path";
  };
  {  // a pressure that is not a number
    v1::CompareRequest r = compare_request(dataset_dir());
    std::string& json = *r.mutable_dataset()->mutable_sessions(1)->mutable_session_json();
    const size_t at = json.find("0.6");
    ASSERT_NE(at, std::string::npos) << json;
    json.replace(at, 3, "\"high\"");
    expect_refused(r, {"tiny/sweep/session.json", "steps[1]", "kpa"});
  }
  {  // not JSON at all
    v1::CompareRequest r = compare_request(dataset_dir());
    r.mutable_dataset()->mutable_sessions(0)->set_session_json("{\"format\": ");
    expect_refused(r, {"tiny/jammed/session.json", "invalid JSON"});
  }
  {  // a frame the session names but the upload lacks
    v1::CompareRequest r = compare_request(dataset_dir());
    r.mutable_dataset()->mutable_sessions(0)->mutable_files()->RemoveLast();
    expect_refused(r, {"tiny/jammed/frames/001.csv"});
  }
  {  // a frame that escapes its session folder
    v1::CompareRequest r = compare_request(dataset_dir());
    r.mutable_dataset()->mutable_sessions(0)->mutable_files(0)->set_path("../../escape.csv");
    expect_refused(r, {"tiny/jammed files[0]", "../../escape.csv", "relative path"});
  }
  {  // a file where a folder of another is
    v1::CompareRequest r = compare_request(dataset_dir());
    v1::SessionFile* clash = r.mutable_dataset()->mutable_sessions(0)->add_files();
    clash->set_path("frames/000.csv/x.csv");
    expect_refused(r, {"tiny/jammed files[2]", "frames/000.csv/x.csv"});
  }
  {  // a broken params document
    v1::CompareRequest r = compare_request(dataset_dir());
    r.mutable_options()->set_params_json(R"({"format": "hapticjam.params/1", "surface": {"mass_kg": -1}})");
    expect_refused(r, {"options.params_json", "mass_kg"});
  }
  // The server still serves a good request.
  EXPECT_TRUE(refused(compare_request(dataset_dir())).ok());
}

// A fit of every optional effect on demo-bending: hours of replays if it
// were left to run. The only worker is freed when the caller cancels.
TEST_F(CalibrationService, CancellingAFitOrDiagnosisFreesTheWorker) {
  ScratchDir dir;
  TestServer s(options(1, 0, dir.path / "q.db"), false);
  Client c(s);
  auto compare_status = [&] {
    auto context = call("", 60);
    auto reader = c.stub->Compare(context.get(), compare_request(dataset_dir()));
    return read_all(*reader).status;
  };

  v1::FitRequest fit;
  *fit.mutable_dataset() = upload(kBending);
  for (const auto& name : EffectRegistry::instance().names()) {
    const auto base = EffectRegistry::instance().baseline_names();
    if (std::find(base.begin(), base.end(), name) == base.end()) fit.mutable_options()->add_effects(name);
  }
  fit.mutable_options()->set_max_iterations(1000);
  v1::DiagnoseRequest diagnose;
  *diagnose.mutable_dataset() = upload(kBending);
  diagnose.set_no_screening(true);

  for (const char* which : {"Fit", "Diagnose"}) {
    SCOPED_TRACE(which);
    auto context = call("", 600);
    v1::FitEvent fit_event;
    v1::DiagnoseEvent diagnose_event;
    std::unique_ptr<grpc::ClientReader<v1::FitEvent>> fit_reader;
    std::unique_ptr<grpc::ClientReader<v1::DiagnoseEvent>> diagnose_reader;
    if (std::string(which) == "Fit") {
      fit_reader = c.stub->Fit(context.get(), fit);
      ASSERT_TRUE(fit_reader->Read(&fit_event));
      ASSERT_TRUE(fit_event.has_progress());
    } else {
      diagnose_reader = c.stub->Diagnose(context.get(), diagnose);
      ASSERT_TRUE(diagnose_reader->Read(&diagnose_event));
      ASSERT_TRUE(diagnose_event.has_progress());
    }
    // It holds the only worker and nothing may wait: refused at once.
    EXPECT_EQ(compare_status().error_code(), StatusCode::RESOURCE_EXHAUSTED);
    context->TryCancel();
    const grpc::Status ended = fit_reader ? fit_reader->Finish() : diagnose_reader->Finish();
    EXPECT_EQ(ended.error_code(), StatusCode::CANCELLED);
    // The worker comes back (bounded wait; it would be busy for hours).
    grpc::Status next;
    EXPECT_TRUE(eventually([&] { return (next = compare_status()).error_code() != StatusCode::RESOURCE_EXHAUSTED; }, 60));
    EXPECT_TRUE(next.ok()) << next.error_message();
  }
}

TEST_F(CalibrationService, ADeadlineStopsADiagnosisAndFreesTheWorker) {
  ScratchDir dir;
  TestServer s(options(1, 1, dir.path / "q.db"), false);
  Client c(s);
  v1::DiagnoseRequest request;
  *request.mutable_dataset() = upload(kBending);
  request.set_no_screening(true);
  auto context = call("", 3);
  auto reader = c.stub->Diagnose(context.get(), request);
  EXPECT_EQ(read_all(*reader).status.error_code(), StatusCode::DEADLINE_EXCEEDED);
  // Queued behind the diagnosis, this would wait for minutes without the stop.
  auto next_context = call("", 60);
  auto next = c.stub->Compare(next_context.get(), compare_request(dataset_dir()));
  const grpc::Status status = read_all(*next).status;
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST_F(CalibrationService, TheServersLimitStopsADiagnosisWhateverTheCallersDeadline) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 1, dir.path / "q.db");
  o.limits.max_calibration_time = std::chrono::seconds(2);
  TestServer s(o, false);
  Client c(s);
  v1::DiagnoseRequest request;
  *request.mutable_dataset() = upload(kBending);
  request.set_no_screening(true);
  auto context = call("", 60);
  auto reader = c.stub->Diagnose(context.get(), request);
  const grpc::Status status = read_all(*reader).status;
  EXPECT_EQ(status.error_code(), StatusCode::DEADLINE_EXCEEDED);
  EXPECT_NE(status.error_message().find("--max-calibration-seconds"), std::string::npos) << status.error_message();
  auto next_context = call("", 60);
  auto next = c.stub->Compare(next_context.get(), compare_request(dataset_dir()));
  const grpc::Status next_status = read_all(*next).status;
  EXPECT_TRUE(next_status.ok()) << next_status.error_message();
}

TEST_F(CalibrationService, APreviewerMayCompareButNotFitOrDiagnose) {
  ScratchDir dir;
  std::ofstream(dir.path / "auth.txt") << "alice operator alice-token-1\ncarol preview carol-token-3\n";
  server::ServerOptions o = options(1, 4, dir.path / "q.db");
  o.auth_file = (dir.path / "auth.txt").string();
  TestServer s(o, false);
  Client c(s);
  v1::FitRequest fit;
  *fit.mutable_dataset() = upload(dataset_dir());
  auto fit_context = call("carol-token-3");
  auto fit_reader = c.stub->Fit(fit_context.get(), fit);
  const grpc::Status refused = read_all(*fit_reader).status;
  EXPECT_EQ(refused.error_code(), StatusCode::PERMISSION_DENIED);
  for (const char* part : {"carol", "preview", "operator"})
    EXPECT_NE(refused.error_message().find(part), std::string::npos) << refused.error_message();
  v1::DiagnoseRequest diagnose;
  *diagnose.mutable_dataset() = upload(dataset_dir());
  auto diagnose_context = call("carol-token-3");
  auto diagnose_reader = c.stub->Diagnose(diagnose_context.get(), diagnose);
  EXPECT_EQ(read_all(*diagnose_reader).status.error_code(), StatusCode::PERMISSION_DENIED);
  auto compare_context = call("carol-token-3");
  auto compare_reader = c.stub->Compare(compare_context.get(), compare_request(dataset_dir()));
  const grpc::Status compared = read_all(*compare_reader).status;
  EXPECT_TRUE(compared.ok()) << compared.error_message();
  auto anonymous_context = call();
  auto anonymous = c.stub->Compare(anonymous_context.get(), compare_request(dataset_dir()));
  EXPECT_EQ(read_all(*anonymous).status.error_code(), StatusCode::UNAUTHENTICATED);
}

}  // namespace
}  // namespace hj
