// Like with like (calib/like_with_like.h): a candidate whose refit only
// carried the current model out of a poor optimum is caught by replaying
// the current model at the candidate's optimum with the effect switched
// off, and refitting it from there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "calib/dataset.h"
#include "calib/like_with_like.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

ModelParams surface(double mass, double k, double kappa_jam) {
  ModelParams p;
  p.surface.mass_kg = mass;
  p.surface.spring_k = k;
  p.surface.kappa_jam = kappa_jam;
  return p;
}

// A "fit" standing at `params`: what the recheck reads of the current
// model is its parameters and RMSE.
LeastSquaresResult standing_at(const Dataset& d, const ModelParams& params, const ReplayOptions& replay) {
  LeastSquaresResult fit;
  fit.params = params;
  const Eigen::VectorXd r = dataset_residuals(d, params, replay);
  fit.residual_count = r.size();
  fit.sum_sq_mm2 = r.squaredNorm();
  fit.rmse_mm = std::sqrt(fit.sum_sq_mm2 / r.size());
  return fit;
}

TEST(LikeWithLike, SwitchingTheAddedEffectOffKeepsEverythingElse) {
  ModelParams p = with_effects(surface(0.5, 60.0, 4.0), {"bending", "pressure_offset"});
  const ModelParams off = without_effect(p, "pressure_offset");
  EXPECT_EQ(off.effects, std::vector<std::string>{"bending"});
  EXPECT_EQ(off.effect_parameters.count("pressure_offset"), 0u);
  EXPECT_EQ(off.effect_parameters.at("bending"), p.effect_parameters.at("bending"));
  EXPECT_EQ(off.surface.mass_kg, 0.5);
  EXPECT_EQ(off.surface.spring_k, 60.0);
  EXPECT_EQ(off.surface.kappa_jam, 4.0);
}

TEST(LikeWithLike, ACandidateThatOnlyLeftAPoorOptimumHandsTheCurrentModelABetterFit) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true);
  LeastSquaresOptions options;
  options.max_iterations = 6;
  const auto parameters = fit_parameters({});
  // The current model stuck far from the data's parameters (M 0.52, k 58).
  const LeastSquaresResult current = standing_at(d, surface(0.45, 75.0, 4.2), options.replay);
  ASSERT_GT(current.rmse_mm, 1.3) << "the current model is not off: the test proves nothing";

  // A candidate that switched pressure_offset on at its neutral defaults
  // (gain 1, offset 0) and found the data's surface parameters.
  const ModelParams candidate = with_effects(surface(0.52, 58.0, 4.2), {"pressure_offset"});
  const LikeWithLike check =
      refit_from_candidate_optimum(d, current, parameters, candidate, "pressure_offset", 0.005, options);
  // The effect is off there, and the model the candidate extends fits at
  // the noise floor: the candidate's gain is that model's.
  EXPECT_LT(check.stripped_rmse_mm, 1.1);
  ASSERT_TRUE(check.refit.has_value());
  EXPECT_TRUE(check.refit->params.effects.empty());
  EXPECT_LE(check.refit->rmse_mm, check.stripped_rmse_mm + 1e-3);
  EXPECT_NEAR(check.refit->params.surface.mass_kg, 0.52, 0.52 * 0.03);
  EXPECT_NEAR(check.refit->params.surface.spring_k, 58.0, 58.0 * 0.03);
}

TEST(LikeWithLike, ACandidateWhoseEffectCarriesItsGainIsNotRechecked) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true);
  LeastSquaresOptions options;
  const auto parameters = fit_parameters({});
  // The current model at the data's parameters; a candidate that adds a
  // bending stiffness (the data has none) and had the mass moved to make
  // up for it. Without the effect that point fits worse: no refit.
  const LeastSquaresResult current = standing_at(d, surface(0.52, 58.0, 4.2), options.replay);
  ModelParams candidate = with_effects(surface(0.49, 58.0, 4.2), {"bending"});
  const LikeWithLike check = refit_from_candidate_optimum(d, current, parameters, candidate, "bending", 0.005, options);
  EXPECT_GT(check.stripped_rmse_mm, current.rmse_mm);
  EXPECT_FALSE(check.refit.has_value());
}

}  // namespace
}  // namespace hj
