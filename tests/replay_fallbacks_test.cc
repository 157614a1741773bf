// ReplayOptions::fallbacks: a session step that only the simulator's
// fallbacks can settle (the jammed 4 x 6 sag raised to 1 kPa must snap up,
// snap_through_test.cc) replays with them, and without them fails at once
// with the usual error naming the step, instead of settling somewhere else.
#include <gtest/gtest.h>

#include <fstream>

#include "calib/replay.h"
#include "calib/residuals.h"
#include "calib/session.h"
#include "scratch_dir.h"

namespace hj {
namespace {

Session jammed_sag_session(const testing_support::ScratchDir& dir) {
  std::string steps;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 6; ++c) steps += R"({"op": "jam", "cell": [)" + std::to_string(r) + ", " + std::to_string(c) + "]}, ";
  std::ofstream(dir.path / "session.json") << R"({
    "format": "hapticjam.session/1", "name": "snap",
    "device": {"rows": 4, "cols": 6, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
    "grid": {"nx": 58, "ny": 39, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 4.0, "dy_mm": 4.0},
    "steps": [)" + steps + R"({"op": "set_pressure", "kpa": 1.0}, {"op": "capture", "frame": "frames/000.csv"}]})";
  return read_session(dir.path);
}

ModelParams paper_device(const Session& session) {
  ModelParams params;
  params.surface = SurfaceParameters::paper_defaults(session.device.geometry());
  return params;
}

ReplayOptions short_budget(bool fallbacks) {
  ReplayOptions options;
  options.solver.max_iterations = 150;  // the static solver fails here anyway; keep it quick
  options.fallback_max_steps = 0;       // the implicit flow is the fallback that settles it
  options.fallbacks = fallbacks;
  return options;
}

TEST(ReplayFallbacks, SettleTheSnapThroughWhenOn) {
  testing_support::ScratchDir dir("snap-on");
  const Session session = jammed_sag_session(dir);
  const ModelParams params = paper_device(session);
  const auto frames = replay_session(session, 4, params.surface, simulator_options(params, short_budget(true)));
  ASSERT_EQ(frames.size(), 1u);
  // Snapped up: the centre of the 4 x 6 array bulges (+61 mm in snap_through_test.cc).
  const auto& h = frames[0].heights_mm;
  EXPECT_GT(h(h.rows() / 2, h.cols() / 2), 40.0);
}

TEST(ReplayFallbacks, OffTheStepFailsAndIsNamed) {
  testing_support::ScratchDir dir("snap-off");
  const Session session = jammed_sag_session(dir);
  const ModelParams params = paper_device(session);
  try {
    replay_session(session, 4, params.surface, simulator_options(params, short_budget(false)));
    FAIL() << "replayed without the fallbacks";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("steps[24]"), std::string::npos) << what;
    EXPECT_NE(what.find("no static equilibrium"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace hj
