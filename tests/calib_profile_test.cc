// Honest intervals (calib/profile_likelihood.h, calib/levelling.h): the
// profile-likelihood interval equals the linearised one where the model is
// linear (design effect included), follows a flat, lopsided cost where it is
// not, stops at a bound or where the model cannot replay; the levelling
// crossing's interval covers the true crossing as often as it claims.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>

#include "calib/levelling.h"
#include "calib/profile_likelihood.h"
#include "expect_error.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

// A fixed pseudo-random sequence, uniform in [-1, 1].
class Uniform {
 public:
  double next() {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state_ >> 11) / static_cast<double>(1ull << 53) * 2.0 - 1.0;
  }
  double gaussian() {
    // Box-Muller.
    const double u = 0.5 * (next() + 1.0) + 1e-300, v = 0.5 * (next() + 1.0);
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
  }

 private:
  unsigned long long state_ = 2026;
};

TEST(ProfileInterval, EqualsTheLinearisedIntervalForALinearModelWithCorrelatedCaptures) {
  // y = a + b t + e over 30 captures of 40 samples; each capture shares an
  // offset (the model's miss), so the design effect is well above 1.
  const int clusters = 30, per = 40, n = clusters * per;
  Eigen::MatrixXd j(n, 2);
  Eigen::VectorXd y(n);
  std::vector<long> rows = {0};
  Uniform random;
  for (int c = 0; c < clusters; ++c) {
    const double shared = random.next();
    for (int s = 0; s < per; ++s) {
      const int i = c * per + s;
      const double t = i / double(n);
      j.row(i) << 1.0, t;
      y[i] = 2.0 + 3.0 * t + shared + 0.3 * random.next();
    }
    rows.push_back(rows.back() + per);
  }
  const Eigen::Vector2d beta = j.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd r = j * beta - y;
  const Eigen::MatrixXd covariance = parameter_covariance(j, r, rows);
  const double halfwidth = 1.96 * std::sqrt(covariance(1, 1));

  ProfileSearch search;
  search.value = beta[1];
  search.min_cost = r.squaredNorm();
  search.threshold = profile_threshold(j, r, rows, 1);
  search.step = halfwidth;
  search.lower = -100.0;
  search.upper = 100.0;
  search.tolerance = 0.05 * halfwidth;
  // The design effect enters: the threshold is several times chi2 s^2.
  EXPECT_GT(search.threshold, 3.0 * kChi2OneDof95 * r.squaredNorm() / (n - 2));
  // The profile: a refitted for each b in closed form.
  const ProfileCost cost = [&](double b, int) {
    const Eigen::VectorXd rest = y - b * j.col(1);
    return (rest.array() - rest.mean()).matrix().squaredNorm();
  };
  const ProfileInterval p = profile_interval(cost, search);
  EXPECT_NEAR(p.low, beta[1] - halfwidth, 1e-3 * halfwidth);
  EXPECT_NEAR(p.high, beta[1] + halfwidth, 1e-3 * halfwidth);
  EXPECT_FALSE(p.low_open);
  EXPECT_FALSE(p.high_open);
  EXPECT_LE(p.evaluations, 8);
}

// A jammed bending stiffness: the surface moves as 1 / kappa, so the cost
// is S0 + A (1 / kappa - 1 / kappa_hat)^2, flat on the stiff side.
struct StiffnessCost {
  double kappa_hat = 3.3, s0 = 1000.0, a = 1.0;
  double operator()(double kappa) const { return s0 + a * std::pow(1.0 / kappa - 1.0 / kappa_hat, 2); }
  // The linearised half-width for a cost rise t: the curvature at kappa_hat
  // is 2 A / kappa_hat^4.
  double linear_halfwidth(double t) const { return std::sqrt(t / a) * kappa_hat * kappa_hat; }
};

ProfileSearch stiffness_search(const StiffnessCost& c, double threshold) {
  ProfileSearch s;
  s.value = c.kappa_hat;
  s.min_cost = c.s0;
  s.threshold = threshold;
  s.step = c.linear_halfwidth(threshold);
  s.lower = 0.01;
  s.upper = 50.0;
  s.tolerance = 0.05 * s.step;
  return s;
}

TEST(ProfileInterval, FollowsAFlatLopsidedCostWhereTheLinearisedIntervalMissesTheTruth) {
  StiffnessCost c;
  // The stiff end at 4.5 exactly: 1 / 3.3 - 1 / 4.5 = d, A d^2 = threshold.
  const double d = 1.0 / 3.3 - 1.0 / 4.5, threshold = 10.0;
  c.a = threshold / (d * d);
  const ProfileSearch search = stiffness_search(c, threshold);
  const ProfileInterval p = profile_interval([&](double k, int) { return c(k); }, search);
  EXPECT_NEAR(p.high, 4.5, 0.02);
  EXPECT_NEAR(p.low, 1.0 / (1.0 / 3.3 + d), 0.02);  // 2.6047
  // Lopsided: the stiff side is much longer than the soft one.
  EXPECT_GT(p.high - c.kappa_hat, 1.5 * (c.kappa_hat - p.low));
  // A true 4.2 lies in the profile interval, not in the symmetric one.
  EXPECT_LT(c.kappa_hat + search.step, 4.2);
  EXPECT_LT(p.low, 4.2);
  EXPECT_GT(p.high, 4.2);
}

TEST(ProfileInterval, EndsAtTheBoundWhereTheCostNeverRisesEnough) {
  StiffnessCost c;
  // Even an infinitely stiff jam raises the cost by only A / kappa_hat^2,
  // less than the threshold: the stiff end is open.
  const double threshold = 10.0;
  c.a = 0.5 * threshold * c.kappa_hat * c.kappa_hat;
  const ProfileInterval p = profile_interval([&](double k, int) { return c(k); }, stiffness_search(c, threshold));
  EXPECT_TRUE(p.high_open);
  EXPECT_EQ(p.high, 50.0);
  EXPECT_FALSE(p.low_open);
  EXPECT_NEAR(p.low, 1.0 / (1.0 / 3.3 + std::sqrt(threshold / c.a)), 0.02);
}

TEST(ProfileInterval, AValueTheModelCannotReplayCountsAsOutside) {
  StiffnessCost c;
  c.a = 1e-6;  // nearly flat everywhere
  int calls = 0;
  const ProfileCost cost = [&](double k, int) {
    ++calls;
    if (k > 4.0) throw std::runtime_error("no equilibrium");
    return c(k);
  };
  ProfileSearch search = stiffness_search(c, 10.0);
  search.step = 0.5;
  search.tolerance = 0.01;
  const ProfileInterval p = profile_interval(cost, search);
  EXPECT_FALSE(p.high_open);
  EXPECT_LE(p.high, 4.0);
  EXPECT_GT(p.high, 4.0 - 0.02);
  EXPECT_EQ(calls, p.evaluations);
}

TEST(ProfileLooseParameters, NamesAParameterItCannotProfile) {
  // A fit that estimated only spring_k: kappa_jam was held.
  const std::vector<FitParameter> parameters = fit_parameters({});
  LeastSquaresResult fit;
  for (size_t k = 0; k < parameters.size(); ++k) {
    fit.estimates.push_back({parameters[k], 1.0});
    if (parameters[k].spec.name == "spring_k") fit.active.push_back(static_cast<int>(k));
  }
  testing_support::expect_error<std::invalid_argument>(
      [&] { profile_loose_parameters(Dataset{}, parameters, {}, {}, fit, {}, {"kappa_jam"}); },
      {"kappa_jam", "not a parameter the fit estimated"});
}

// A linearised interval much narrower than the cost says (here made so by
// hand; on demo-baseline by a finite-difference Jacobian next to a jump in
// a jammed capture) is checked at its ends, where the cost barely rises,
// and replaced by the profile, which is wider.
TEST(ProfileLooseParameters, ProfilesALinearisedIntervalTheCostDoesNotBear) {
  const fs::path sessions = fs::path(HJ_SHARED_DIR) / "data/sessions";
  const Dataset d = select_sessions(read_dataset(sessions / "demo-baseline"), {"jammed-sweep"}, true);
  std::vector<FitParameter> parameters;
  for (const auto& p : fit_parameters({}))
    if (p.spec.name == "kappa_jam") parameters.push_back(p);
  LeastSquaresOptions options;
  options.replay.threads = 2;
  ModelParams start;  // demo-baseline's README
  start.surface.mass_kg = 0.52;
  start.surface.spring_k = 58.0;
  start.surface.kappa_jam = 4.2;
  LeastSquaresResult fit = fit_least_squares(d, start, parameters, options);
  ASSERT_EQ(fit.active.size(), 1u);
  ParameterEstimate& e = fit.estimates[fit.active[0]];
  const double honest = e.ci95_high - e.ci95_low;
  e.std_error *= 1e-3;
  e.ci95_low = e.value - 1.96 * e.std_error;
  e.ci95_high = e.value + 1.96 * e.std_error;
  e.loose = false;
  profile_loose_parameters(d, parameters, options, {}, fit);
  EXPECT_EQ(e.interval_method, "profile likelihood");
  EXPECT_GT(e.ci95_high - e.ci95_low, 0.1 * honest) << e.ci95_low << " .. " << e.ci95_high;
  EXPECT_LT(e.ci95_low, e.value);
  EXPECT_GT(e.ci95_high, e.value);
}

// Centre heights of a net without pre-tension around its levelling
// pressure: h = a cbrt(P - P0) + noise, at the demo sweep's pressures.
std::vector<std::pair<double, double>> sweep(double p0, double sigma, Uniform& random) {
  std::vector<std::pair<double, double>> points;
  for (int k = 0; k <= 10; ++k) {
    const double p = 241.0 * k;
    points.push_back({p, 2.4 * std::cbrt(p - p0) + sigma * random.gaussian()});
  }
  return points;
}

TEST(LevellingInterval, IntervalCoversTheTrueCrossingAsOftenAsItClaims) {
  Uniform random;
  const double p0 = 294.4;
  int covered = 0;
  double width = 0.0;
  constexpr int kTrials = 300;
  for (int trial = 0; trial < kTrials; ++trial) {
    const CubeRootCrossing c = fit_cube_root_crossing(sweep(p0, 0.5, random), 241.0, 482.0);
    EXPECT_LE(c.low_pa, c.pressure_pa);
    EXPECT_GE(c.high_pa, c.pressure_pa);
    covered += c.low_pa <= p0 && p0 <= c.high_pa;
    width += (c.high_pa - c.low_pa) / kTrials;
  }
  // 95 % nominal; 300 trials give a standard error of 1.3 %.
  EXPECT_GT(covered, 0.90 * kTrials);
  EXPECT_LT(covered, 0.99 * kTrials);
  // Set by the scatter: ten times the noise, about ten times the width.
  Uniform again;
  double wide = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const CubeRootCrossing c = fit_cube_root_crossing(sweep(p0, 5.0, again), 241.0, 482.0);
    wide += (c.high_pa - c.low_pa) / 50;
  }
  EXPECT_GT(wide, 5.0 * width);
}

TEST(LevellingInterval, TwoPointsGiveTheirBracket) {
  const CubeRootCrossing c = fit_cube_root_crossing({{241.0, -3.0}, {482.0, 4.0}}, 241.0, 482.0);
  EXPECT_EQ(c.low_pa, 241.0);
  EXPECT_EQ(c.high_pa, 482.0);
  EXPECT_GT(c.pressure_pa, 241.0);
  EXPECT_LT(c.pressure_pa, 482.0);
}

TEST(LevellingInterval, DemoBaselineMassIntervalHoldsTheStatedMass) {
  const LevellingEstimate e = levelling_mass(read_dataset(std::filesystem::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline"), 9.81);
  ASSERT_TRUE(e.found);
  EXPECT_LT(e.mass_low_kg, 0.52);
  EXPECT_GT(e.mass_high_kg, 0.52);
  EXPECT_LE(e.mass_low_kg, e.mass_kg);
  EXPECT_GE(e.mass_high_kg, e.mass_kg);
  EXPECT_NEAR(e.mass_low_kg, e.pressure_low_pa * 12 * 0.038 * 0.038 / 9.81, 1e-12);
  // From the two captures either side of the crossing (241 Pa apart):
  // far wider than the joint fit's 1e-5 kg, narrower than that bracket.
  EXPECT_EQ(e.points, 4);
  EXPECT_LT(e.pressure_high_pa - e.pressure_low_pa, e.above_pa - e.below_pa);
  EXPECT_GT(e.mass_high_kg - e.mass_low_kg, 0.01 * 0.52);
}

}  // namespace
}  // namespace hj
