// `hapticjam remote compare|fit` against the real hapticjam-server: the CLI
// uploads a dataset folder, shows the server's stages and writes the
// documents it returns; summary.json, report.html and the heat maps are
// the library's comparison of the
// same data, params.json loads as --params does, and a malformed session
// is refused with exit 13 naming the file and key.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "calib/calibration_json.h"
#include "calib/report/compare_report.h"
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

TEST(RemoteCalibrationCli, CompareAndFitWriteTheServersDocuments) {
  testing_support::ScratchDir dir;
  testing_support::Server server(dir.path, dir.path / "queue.db");
  const fs::path dataset = small_dataset(dir.path);
  auto cli = [&](const std::vector<std::string>& args) {
    std::vector<std::string> all = {"remote"};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"--server", server.address(), "--timeout", "300"});
    return testing_support::run_cli(all, dir.path);
  };

  const CliResult compared = cli({"compare", dataset.string(), "--segments", "2", "--out", (dir.path / "cmp").string()});
  ASSERT_EQ(compared.code, 0) << compared.err;
  EXPECT_NE(compared.err.find("compare: 2/2"), std::string::npos) << "the server's progress is shown: " << compared.err;
  const Dataset local = read_dataset(dataset);
  ModelParams params;
  params.surface = SurfaceParameters::paper_defaults(local.device().geometry(2));
  params.surface.max_pressure_pa = local.device().max_pressure_kpa * 1000.0;
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

}  // namespace
}  // namespace hj
