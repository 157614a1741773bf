// The fit (calib/least_squares.h, stiffness_bisection.h, cross_validation.h)
// on the shared demo-baseline data, on its cheap sessions so that the test
// stays short: the true parameters come back within their intervals, the
// parameters the captures do not depend on are held and said so, and the
// held-out error of the right model is at the sensor's noise floor.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "calib/cross_validation.h"
#include "calib/diagnosis.h"
#include "calib/fit_model.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";
constexpr double kTrueMass = 0.52, kTrueK = 58.0;

// The unjammed pressure sweep and a mixed session (no jammed sweep, whose
// many jammed settles cost the most).
Dataset cheap_sessions() { return select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true); }

ModelParams off_start() {
  ModelParams p;
  p.surface.mass_kg = 0.50;
  p.surface.spring_k = 64.5;
  p.surface.kappa_jam = 4.79;
  return p;
}

const ParameterEstimate& estimate(const LeastSquaresResult& fit, const std::string& name) {
  for (const auto& e : fit.estimates)
    if (e.parameter.qualified_name() == name) return e;
  throw std::runtime_error("no estimate " + name);
}

TEST(FitParameters, ComeFromTheRegistry) {
  const auto base = fit_parameters({});
  std::vector<std::string> names;
  for (const auto& p : base) names.push_back(p.qualified_name());
  for (const char* n : {"mass_kg", "spring_k", "kappa_jam"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  ModelParams params;
  for (const auto& p : base) {
    set_parameter_value(params, p, p.spec.upper);
    EXPECT_EQ(parameter_value(params, p), p.spec.upper) << p.qualified_name();
  }
  EXPECT_THROW(fit_parameters({"no_such_effect"}), std::invalid_argument);
}

TEST(StiffnessBisection, FindsTheSpringStiffnessOfTheUnjammedCaptures) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep"}, true);
  ModelParams start = off_start();
  start.surface.mass_kg = kTrueMass;
  const auto parameters = fit_parameters({});
  const FitParameter* k = nullptr;
  for (const auto& p : parameters)
    if (p.spec.name == "spring_k") k = &p;
  ASSERT_NE(k, nullptr);
  BisectionOptions options;
  options.iterations = 8;
  const BisectionResult r = fit_stiffness_by_bisection(
      d, start, *k, [](const MeasuredCapture& c) { return c.jammed_count() == 0; }, options);
  ASSERT_TRUE(r.bracketed);
  EXPECT_EQ(r.captures, 11);
  EXPECT_NEAR(r.value, kTrueK, 0.05 * kTrueK);
}

TEST(LeastSquares, RecoversTheTrueParametersWithHonestIntervals) {
  const Dataset d = cheap_sessions();
  LeastSquaresOptions options;
  options.max_iterations = 12;
  const LeastSquaresResult fit = fit_least_squares(d, off_start(), fit_parameters({}), options);
  const auto& mass = estimate(fit, "mass_kg");
  const auto& k = estimate(fit, "spring_k");
  EXPECT_NEAR(mass.value, kTrueMass, 0.03 * kTrueMass);
  EXPECT_NEAR(k.value, kTrueK, 0.03 * kTrueK);
  // The truth lies within three standard errors (a 95 % interval, 1.96
  // of them, misses it one time in twenty), and the intervals are tight.
  EXPECT_NEAR(mass.value, kTrueMass, 3.0 * mass.std_error) << "std error " << mass.std_error;
  EXPECT_NEAR(k.value, kTrueK, 3.0 * k.std_error) << "std error " << k.std_error;
  EXPECT_NEAR(mass.ci95_high - mass.ci95_low, 2.0 * 1.96 * mass.std_error, 1e-12);
  EXPECT_LT(k.ci95_high - k.ci95_low, 0.02 * kTrueK);
  // The damping acts only in dynamics: it changes no settled capture.
  EXPECT_FALSE(estimate(fit, "damping_b").active);
  // At the optimum, only the camera's noise is left (about 1.04 mm).
  EXPECT_NEAR(fit.rmse_mm, noise_floor_mm(d), 0.05);
  EXPECT_GT(fit.r2, 0.99);
  EXPECT_EQ(fit.residual_count, fit.residuals.size());
  EXPECT_EQ(fit.session_rows.size(), d.sessions.size() + 1);

  // Held out, each session is predicted as well as when it is fitted.
  const CrossValidation cv = cross_validate(d, fit_parameters({}), fit, options.replay);
  EXPECT_NEAR(cv.heldout_rmse_mm, fit.rmse_mm, 0.05);
  EXPECT_GE(cv.heldout_rmse_mm, fit.rmse_mm - 1e-3);
}

// A fit that is only a start takes no Jacobian where it ends: the same
// point and cost as the full fit of as many iterations, in fewer replays.
TEST(LeastSquares, AStartWithoutItsFinalJacobianEndsOnTheSamePointInFewerReplays) {
  const Dataset d = cheap_sessions();
  LeastSquaresOptions options;
  options.max_iterations = 2;
  options.replay.threads = 1;
  const LeastSquaresResult full = fit_least_squares(d, off_start(), fit_parameters({}), options);
  options.final_jacobian = false;
  const LeastSquaresResult start = fit_least_squares(d, off_start(), fit_parameters({}), options);
  ASSERT_EQ(full.iterations, 3) << "both steps must be taken, or this test shows nothing";
  EXPECT_EQ(start.sum_sq_mm2, full.sum_sq_mm2);
  EXPECT_EQ(model_params_json(start.params), model_params_json(full.params));
  EXPECT_EQ(start.jacobians, full.jacobians - 1);
  EXPECT_EQ(start.jacobian.size(), 0);
  EXPECT_TRUE(std::isnan(estimate(start, "spring_k").std_error));
  EXPECT_FALSE(start.converged);

  // One iteration still takes its step: only the Jacobian after it is left out.
  options.max_iterations = 1;
  const LeastSquaresResult one_step = fit_least_squares(d, off_start(), fit_parameters({}), options);
  options.final_jacobian = true;
  const LeastSquaresResult one_full = fit_least_squares(d, off_start(), fit_parameters({}), options);
  EXPECT_EQ(one_step.sum_sq_mm2, one_full.sum_sq_mm2);
  EXPECT_NE(estimate(one_step, "spring_k").value, off_start().surface.spring_k);
}

TEST(Diagnosis, BicPenalisesParametersAndNoiseFloorIsTheSensors) {
  LeastSquaresResult a;
  a.residual_count = 1000;
  a.sum_sq_mm2 = 1000.0;
  a.free_parameters = 3;
  LeastSquaresResult b = a;
  b.free_parameters = 4;
  EXPECT_NEAR(bic(b) - bic(a), std::log(1000.0), 1e-9);
  const Dataset d = cheap_sessions();
  // Accuracy 1 mm (as the noise sigma), rounded to 1 mm: sqrt(1 + 1/12).
  EXPECT_NEAR(noise_floor_mm(d), std::sqrt(1.0 + 1.0 / 12.0), 1e-12);
}

}  // namespace
}  // namespace hj

namespace hj {
namespace {

TEST(ParameterCovariance, IndependentNoiseKeepsTheClassicIntervalCorrelatedMissesWidenIt) {
  // y = a + b t over 40 captures of 50 samples; J = [1, t].
  const int clusters = 40, per = 50, n = clusters * per;
  Eigen::MatrixXd j(n, 2);
  std::vector<long> rows = {0};
  for (int c = 0; c < clusters; ++c) {
    for (int s = 0; s < per; ++s) j.row(c * per + s) << 1.0, (c * per + s) / double(n);
    rows.push_back(rows.back() + per);
  }
  // Independent noise (a fixed pseudo-random sequence): the sandwich agrees
  // with the classic variance to within sampling error, and the classic one
  // is kept where it is the larger.
  Eigen::VectorXd noise(n);
  unsigned state = 12345;
  for (int i = 0; i < n; ++i) {
    state = state * 1103515245u + 12345u;
    noise[i] = ((state >> 8) % 2001) / 1000.0 - 1.0;
  }
  const Eigen::MatrixXd classic = parameter_covariance(j, noise, {});
  const Eigen::MatrixXd iid = parameter_covariance(j, noise, rows);
  for (int k = 0; k < 2; ++k) {
    EXPECT_GE(iid(k, k), classic(k, k));
    EXPECT_LT(iid(k, k), 2.0 * classic(k, k)) << k;
  }
  // The same spread, but each capture missed by one offset: 50 samples that
  // say the same thing are one piece of evidence, so the variance grows
  // about 50-fold.
  Eigen::VectorXd shared(n);
  for (int c = 0; c < clusters; ++c) shared.segment(c * per, per).setConstant(noise[c * per]);
  const Eigen::MatrixXd wide = parameter_covariance(j, shared, rows);
  const Eigen::MatrixXd narrow = parameter_covariance(j, shared, {});
  EXPECT_GT(wide(0, 0), 10.0 * narrow(0, 0));
  EXPECT_GT(wide(1, 1), 10.0 * narrow(1, 1));
}

}  // namespace
}  // namespace hj
