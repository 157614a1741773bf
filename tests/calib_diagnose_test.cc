// Acceptance of the diagnosis (calib/diagnosis.h) on the shared datasets,
// on their cheap sessions (no jammed sweep) and two candidates so that the
// test stays short; the full runs are in the README. On demo-bending the
// missing bending stiffness is found, chosen and fitted; on demo-baseline
// the same code chooses nothing, although the extra freedom lowers the
// fitted error a little.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "calib/diagnosis.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kSessions = fs::path(HJ_SHARED_DIR) / "data/sessions";

Dataset cheap(const std::string& name) {
  return select_sessions(read_dataset(kSessions / name), {"unjammed-sweep", "mixed-1", "mixed-2"}, true);
}

DiagnoseOptions quick_options() {
  DiagnoseOptions o;
  o.candidates = {"bending", "area_pressure"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  return o;
}

TEST(Diagnose, FindsTheBendingStiffnessInDemoBending) {
  const Dataset d = cheap("demo-bending");
  const Diagnosis result = diagnose(d, ModelParams{}, quick_options());
  ASSERT_EQ(result.ranking.size(), 2u) << ::testing::PrintToString(result.skipped);
  EXPECT_EQ(result.ranking[0].added, "bending");
  EXPECT_TRUE(result.ranking[0].significant);
  ASSERT_EQ(result.verdict, std::vector<std::string>{"bending"});
  // Within 20 % of the noise floor, and the stated kappa0 = 0.002 N m/rad within 10 %.
  EXPECT_LT(result.ranking[0].fit.rmse_mm, 1.2 * result.noise_floor_mm);
  EXPECT_GT(result.baseline.joint.rmse_mm, 1.2 * result.noise_floor_mm);
  const auto& params = result.final_params;
  ASSERT_EQ(params.effects, std::vector<std::string>{"bending"});
  const auto& bending = params.effect_parameters.at("bending");
  ASSERT_EQ(bending.size(), 1u);
  EXPECT_NEAR(bending.begin()->second, 0.002, 0.0002);
  // The held-out RMSE pools the folds: one figure and one step per session.
  const CandidateFit& chosen = result.ranking[0];
  ASSERT_EQ(chosen.heldout_session_rmse_mm.size(), d.sessions.size());
  ASSERT_EQ(chosen.fold_step.size(), d.sessions.size());
  const auto [least, most] =
      std::minmax_element(chosen.heldout_session_rmse_mm.begin(), chosen.heldout_session_rmse_mm.end());
  EXPECT_LE(*least, chosen.heldout_rmse_mm + 1e-9);
  EXPECT_GE(*most, chosen.heldout_rmse_mm - 1e-9);
  for (double t : chosen.fold_step) EXPECT_TRUE(t >= 0.0 && t <= 1.0) << t;
  ASSERT_EQ(result.ladder.size(), 2u);
  EXPECT_LT(result.ladder[1].heldout_rmse_mm, result.ladder[0].heldout_rmse_mm);
  // area_pressure is not refitted: screened out, or predicted far above
  // bending's refitted held-out error (DiagnoseOptions::refit_cutoff).
  EXPECT_TRUE(result.ranking[1].screened_out) << result.ranking[1].screening_note;
}

TEST(Diagnose, ChoosesNothingOnDemoBaseline) {
  const Dataset d = cheap("demo-baseline");
  const Diagnosis result = diagnose(d, ModelParams{}, quick_options());
  EXPECT_TRUE(result.skipped.empty()) << ::testing::PrintToString(result.skipped);
  EXPECT_TRUE(result.verdict.empty());
  for (const auto& c : result.ranking) {
    EXPECT_FALSE(c.significant) << c.added;
    // More freedom never fits worse...
    EXPECT_LE(c.fit.rmse_mm, result.baseline.joint.rmse_mm + 1e-3) << c.added;
  }
  // ...but the baseline is already at the noise floor.
  EXPECT_NEAR(result.baseline.joint.rmse_mm, result.noise_floor_mm, 0.03);
  EXPECT_EQ(result.ladder.size(), 1u);
  EXPECT_EQ(result.pattern.worst_cells.size(), 3u);
}

}  // namespace
}  // namespace hj
