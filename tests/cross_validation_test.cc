// Leave-one-session-out folds (calib/cross_validation.h) checked on their
// training sessions: a fold whose linear step leaps along a direction the
// linearisation gets wrong is cut back to where it does not raise the
// training cost, so the held-out error is that of a refit, not of the leap.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "calib/cross_validation.h"
#include "calib/fit_model.h"
#include "calib/fold_refit.h"
#include "calib_synthetic.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

// Two of demo-baseline's sessions and a short fit's options; the start is
// demo-baseline's true baseline (calib_synthetic.h).
Dataset two_sessions() { return select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true); }

LeastSquaresOptions eight_iterations() {
  LeastSquaresOptions options;
  options.max_iterations = 8;
  return options;
}

double cost_without(const Dataset& d, int held_out, const ModelParams& params, const ReplayOptions& options) {
  double cost = 0.0;
  for (int s = 0; s < static_cast<int>(d.sessions.size()); ++s)
    if (s != held_out) cost += session_residuals(d.sessions[s], params, options).squaredNorm();
  return cost;
}

TEST(CrossValidation, AFoldThatLeapsIsCutBackToWhereItFitsItsTrainingSessions) {
  const Dataset d = two_sessions();
  const LeastSquaresOptions options = eight_iterations();
  const auto parameters = fit_parameters({});
  LeastSquaresResult fit = fit_least_squares(d, testing_support::true_tiny_baseline(), parameters, options);
  ASSERT_GE(fit.active.size(), 2u);

  // The fit's own linearisation: each fold stays close to the optimum, and
  // the held-out error is the in-sample one (the noise floor).
  const CrossValidation plain = cross_validate(d, parameters, fit, options.replay);
  EXPECT_NEAR(plain.heldout_rmse_mm, fit.rmse_mm, 0.05);

  // A linearisation that has the mass 1000 times too weak (as where the
  // model is far from linear): each fold's linear step moves the mass 1000
  // times too far, out of the basin of the data (held out: 10.8 mm).
  int mass = -1;
  for (int k = 0; k < static_cast<int>(fit.active.size()); ++k)
    if (parameters[fit.active[k]].qualified_name() == "mass_kg") mass = k;
  ASSERT_GE(mass, 0);
  fit.jacobian.col(mass) *= 1e-3;
  CrossValidationOptions unchecked;
  unchecked.max_halvings = -1;
  const CrossValidation leapt = cross_validate(d, parameters, fit, options.replay, unchecked);
  EXPECT_GT(leapt.heldout_rmse_mm, 1.5 * fit.rmse_mm) << "the leap does not show: the test proves nothing";

  // Ten halvings take the step back to 1000 / 1024 of the right one.
  CrossValidationOptions halving;
  halving.max_halvings = 10;
  const CrossValidation checked = cross_validate(d, parameters, fit, options.replay, halving);
  // Cut back, the folds predict their held-out sessions as the right
  // linearisation's folds do.
  EXPECT_NEAR(checked.heldout_rmse_mm, plain.heldout_rmse_mm, 0.01);
  for (int s = 0; s < static_cast<int>(d.sessions.size()); ++s) {
    const double t = checked.fold_step[s];
    EXPECT_GT(t, 0.0) << "fold " << s << " dropped its step";
    EXPECT_LT(t, 1.0) << "fold " << s << " took the leap";
    EXPECT_EQ(std::exp2(std::round(std::log2(t))), t) << t;
    EXPECT_LE(cost_without(d, s, checked.fold_params[s], options.replay),
              cost_without(d, s, fit.params, options.replay) * (1.0 + 1e-12))
        << "fold " << s << " raised its training cost (step " << t << ")";
  }
}

// A fold refitted for real (calib/fold_refit.h) is the fit without the
// held-out session, and where the model is close to linear its held-out
// error is what the one-step fold predicts.
TEST(CrossValidation, AFoldRefitIsTheFitWithoutItsSession) {
  const Dataset d = two_sessions();
  const LeastSquaresOptions options = eight_iterations();
  const auto parameters = fit_parameters({});
  const LeastSquaresResult fit = fit_least_squares(d, testing_support::true_tiny_baseline(), parameters, options);
  const CrossValidation one_step = cross_validate(d, parameters, fit, options.replay);
  for (int s = 0; s < static_cast<int>(d.sessions.size()); ++s) {
    const FoldRefit fold = refit_fold(d, parameters, fit, s, options);
    const Dataset training = select_sessions(d, {d.sessions[s].session.name}, false);
    const LeastSquaresResult direct = fit_least_squares(training, fit.params, parameters, options);
    EXPECT_NEAR(fold.params.surface.mass_kg, direct.params.surface.mass_kg, 1e-9);
    EXPECT_NEAR(fold.params.surface.spring_k, direct.params.surface.spring_k, 1e-6);
    EXPECT_GT(fold.heldout_count, 0);
    EXPECT_NEAR(fold.heldout_rmse_mm, one_step.session_rmse_mm[s], 0.05) << d.sessions[s].session.name;
  }
  // Pooled over the sessions' samples: 100 at 1 mm and 300 at 2 mm.
  EXPECT_NEAR(pooled_heldout_rmse({1.0, 2.0}, {0, 100, 400}), std::sqrt((100.0 + 1200.0) / 400.0), 1e-12);
}

}  // namespace
}  // namespace hj
