// `hapticjam remote compare|fit|diagnose` against the real hapticjam-server:
// the CLI uploads a dataset folder, shows the server's stages and writes the
// documents it returns; summary.json, report.html and the heat maps are the
// library's comparison of the same data, params.json loads as --params does,
// diagnose's report.html is the library's page of the same diagnosis, and a
// malformed session is refused with exit 13 naming the file and key.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "calib/calibration_json.h"
#include "calib/report/compare_report.h"
#include "calib/report/diagnose_report_html.h"
#include "calib/diagnosis.h"
#include "e2e_support.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing_support::CliResult;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

// Two sessions of demo-baseline in a dataset folder of their own.
fs::path small_dataset(const fs::path& dir) {
  const fs::path out = dir / "small";
  for (const char* name : {"unjammed-sweep", "mixed-1"}) {
    fs::create_directories(out / name);
    fs::copy(kBaseline / name, out / name, fs::copy_options::recursive);
  }
  return out;
}

// `hapticjam remote ARGS --server ...` with a generous deadline.
CliResult remote_cli(const testing_support::Server& server, const fs::path& dir, const std::vector<std::string>& args) {
  std::vector<std::string> all = {"remote"};
  all.insert(all.end(), args.begin(), args.end());
  all.insert(all.end(), {"--server", server.address(), "--timeout", "300"});
  return testing_support::run_cli(all, dir);
}

// The server's start without --params: the paper's values for the device.
ModelParams paper_params(const Dataset& dataset, int segments) {
  ModelParams params;
  params.surface = SurfaceParameters::paper_defaults(dataset.device().geometry(segments));
  params.surface.max_pressure_pa = dataset.device().max_pressure_kpa * 1000.0;
  return params;
}

TEST(RemoteCalibrationCli, CompareAndFitWriteTheServersDocuments) {
  testing_support::ScratchDir dir;
  testing_support::Server server(dir.path, dir.path / "queue.db");
  const fs::path dataset = small_dataset(dir.path);
  auto cli = [&](const std::vector<std::string>& args) { return remote_cli(server, dir.path, args); };

  const CliResult compared = cli({"compare", dataset.string(), "--segments", "2", "--out", (dir.path / "cmp").string()});
  ASSERT_EQ(compared.code, 0) << compared.err;
  EXPECT_NE(compared.err.find("compare: 2/2"), std::string::npos) << "the server's progress is shown: " << compared.err;
  const Dataset local = read_dataset(dataset);
  const ModelParams params = paper_params(local, 2);
  ReplayOptions replay;
  replay.segments = 2;
  const Evaluation evaluation = evaluate_dataset(local, params, replay);
  const json summary = json::parse(testing_support::read_file(dir.path / "cmp" / "summary.json"));
  const CompareReport report = compare_report(local, params, evaluation, 5.0);
  EXPECT_EQ(summary, json::parse(report.summary.dump()));
  EXPECT_NEAR(summary["rmse_mm"].get<double>(), evaluation.rmse_mm(), 1e-9);
  // report.html and every heat map, as `hapticjam compare` writes them.
  EXPECT_TRUE(testing_support::read_file(dir.path / "cmp" / "report.html") == report.html);
  ASSERT_EQ(report.maps.size(), static_cast<size_t>(local.capture_count()));
  for (const ReportFile& map : report.maps)
    EXPECT_TRUE(testing_support::read_file(dir.path / "cmp" / map.path) == map.bytes) << map.path;

  const CliResult fitted = cli({"fit", dataset.string(), "--segments", "2", "--max-iterations", "2", "--no-initial",
                                "--holdout", "mixed-1", "--out", (dir.path / "fit").string()});
  ASSERT_EQ(fitted.code, 0) << fitted.err;
  EXPECT_NE(fitted.err.find("least squares"), std::string::npos) << fitted.err;
  EXPECT_NE(fitted.out.find("held-out RMSE"), std::string::npos) << fitted.out;
  const json doc = json::parse(testing_support::read_file(dir.path / "fit" / "params.json"));
  EXPECT_EQ(doc["heldout"]["sessions"], json::array({"mixed-1"}));
  EXPECT_TRUE(doc["heldout"].contains("rmse_mm"));
  EXPECT_NO_THROW(read_model_params(dir.path / "fit" / "params.json", params.surface));
  const std::string fit_html = testing_support::read_file(dir.path / "fit" / "report.html");
  for (const char* part : {"hapticjam fit: small", "Joint bounded least squares", "spring_k", "Held-out sessions"})
    EXPECT_NE(fit_html.find(part), std::string::npos) << part;

  // A session whose step names a cell outside the 3 x 4 array.
  std::ofstream(dataset / "mixed-1" / "session.json") << R"({"format": "hapticjam.session/1",
    "device": {"rows": 3, "cols": 4, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
    "grid": {"nx": 77, "ny": 58, "x0_mm": 0, "y0_mm": 0, "dx_mm": 2, "dy_mm": 2},
    "steps": [{"op": "jam", "cell": [5, 0]}]})";
  const CliResult refused = cli({"compare", dataset.string(), "--out", (dir.path / "bad").string()});
  EXPECT_EQ(refused.code, 13) << refused.err;
  for (const char* part : {"INVALID_ARGUMENT", "small/mixed-1/session.json", "steps[0]", "cell"})
    EXPECT_NE(refused.err.find(part), std::string::npos) << part << " in: " << refused.err;
}

// One cheap candidate on the two sessions: diagnosis.json and params.json
// as the server made them, and report.html byte for byte the page
// `hapticjam diagnose` builds from the same diagnosis (with the server's
// run time, from diagnosis.json).
TEST(RemoteCalibrationCli, DiagnoseWritesTheServersDocumentsAndPage) {
  testing_support::ScratchDir dir;
  testing_support::Server server(dir.path, dir.path / "queue.db");
  const fs::path dataset = small_dataset(dir.path);
  const fs::path out = dir.path / "diag";
  const CliResult diagnosed = remote_cli(server, dir.path,
                                         {"diagnose", dataset.string(), "--segments", "2", "--max-iterations", "2",
                                          "--threads", "1", "--effects", "pressure_offset", "--out", out.string()});
  ASSERT_EQ(diagnosed.code, 0) << diagnosed.err;
  EXPECT_NE(diagnosed.out.find((out / "report.html").string()), std::string::npos) << diagnosed.out;

  const Dataset local = read_dataset(dataset);
  DiagnoseOptions options;
  options.candidates = {"pressure_offset"};
  options.fit.least_squares.max_iterations = 2;
  options.fit.least_squares.replay.segments = 2;
  options.fit.least_squares.replay.threads = 1;
  options.fit.least_squares.replay = fitting_replay(options.fit.least_squares.replay);
  options.fit.bisection.replay = options.fit.least_squares.replay;
  const Diagnosis d = diagnose(local, paper_params(local, 2), options);
  const json doc = json::parse(testing_support::read_file(out / "diagnosis.json"));
  EXPECT_EQ(doc["verdict"], json(d.verdict));
  EXPECT_NEAR(doc["baseline"]["rmse_mm"].get<double>(), d.baseline.joint.rmse_mm, 1e-9);
  EXPECT_NO_THROW(read_model_params(out / "params.json", paper_params(local, 2).surface));
  const std::string html = testing_support::read_file(out / "report.html");
  EXPECT_TRUE(html == diagnose_report_html("small", d, options, {doc["seconds"].get<double>(), std::nullopt}))
      << html;
  EXPECT_NE(html.find("<tr><td>pressure_offset</td>"), std::string::npos);
}

}  // namespace
}  // namespace hj
