// The probe of a converged fit (calib/optimum_probe.h) on the session of
// demo-baseline whose cost is not smooth in the mass: the all-jammed sweep,
// whose captures at 2.16 and 3.02 kPa take another shape below about
// 0.51993 kg (the truth is 0.52). A fit of the mass from the levelling
// estimate's 0.51977 converges in that basin; the probe finds the better
// one, and a fit from there reaches the truth's cost. Its replays stop
// once their cost is past what it could take.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "calib/optimum_probe.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kSessions = fs::path(HJ_SHARED_DIR) / "data/sessions";

ModelParams truth() {
  ModelParams m;  // demo-baseline's README
  m.surface.mass_kg = 0.52;
  m.surface.spring_k = 58.0;
  m.surface.kappa_jam = 4.2;
  return m;
}

std::vector<FitParameter> mass_only() {
  std::vector<FitParameter> out;
  for (const auto& p : fit_parameters({}))
    if (p.spec.name == "mass_kg") out.push_back(p);
  return out;
}

// The optimum the joint fit of the whole dataset converged to (mass
// 0.519771 kg +- 1.28e-5, `hapticjam fit demo-baseline` before the probe),
// as a result of this one session: the probe needs only the values, their
// standard errors and the cost there.
LeastSquaresResult converged_in_the_other_basin(const Dataset& d, const ReplayOptions& replay) {
  LeastSquaresResult fit;
  fit.params = truth();
  fit.params.surface.mass_kg = 0.519771;
  fit.estimates.push_back({mass_only()[0], 0.519771, 1.28e-5, 0.519746, 0.519796});
  fit.sum_sq_mm2 = dataset_sum_of_squares(d, fit.params, replay);
  fit.converged = true;
  return fit;
}

TEST(OptimumProbe, FindsTheBasinAConvergedFitSitsBeside) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"jammed-sweep"}, true);
  ReplayOptions replay = fitting_replay({});
  replay.threads = 2;
  const LeastSquaresResult stuck = converged_in_the_other_basin(d, replay);
  const double at_truth = dataset_sum_of_squares(d, truth(), replay);
  ASSERT_GT(stuck.sum_sq_mm2, 1.05 * at_truth) << "the two basins are no longer there";

  const OptimumProbe probe = probe_optimum(d, stuck, replay);
  EXPECT_EQ(probe.points, 6);  // 10, 30 and 100 standard errors each way
  EXPECT_TRUE(probe.moved);
  // 30 standard errors up, 0.52010 kg: in the truth's basin, a little past it.
  EXPECT_NEAR(probe.best.surface.mass_kg, 0.519771 + 30 * 1.28e-5, 1e-9);
  // Most of the way down to the truth's cost.
  EXPECT_LT(probe.best_sum_sq_mm2 - at_truth, 0.5 * (stuck.sum_sq_mm2 - at_truth))
      << "stuck " << stuck.sum_sq_mm2 << ", probed " << probe.best_sum_sq_mm2 << ", truth " << at_truth << " mm^2";
  EXPECT_EQ(probe.best.surface.spring_k, stuck.params.surface.spring_k);  // one parameter moved at a time
  EXPECT_NE(probe.note.find("mass_kg 0.519771 -> 0.5201"), std::string::npos) << probe.note;
}

// A loose parameter: `hapticjam fit demo-baseline` converged at kappa_jam
// 11.46 +- 8.0 (bounds 0 .. 100), where 10, 30 and 100 standard errors all
// land on a bound. The probe looks between the optimum and the bounds
// instead, and finds the truth's side (4.2).
TEST(OptimumProbe, LooksBetweenALooseParameterAndItsBounds) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"jammed-sweep"}, true);
  ReplayOptions replay = fitting_replay({});
  replay.threads = 2;
  FitParameter kappa_jam;
  for (const auto& p : fit_parameters({}))
    if (p.spec.name == "kappa_jam") kappa_jam = p;
  LeastSquaresResult fit;
  fit.params = truth();
  fit.params.surface.mass_kg = 0.5200213;
  fit.params.surface.spring_k = 57.965721;
  fit.params.surface.kappa_jam = 11.4635;
  fit.estimates.push_back({kappa_jam, 11.4635, 8.0, 11.4635 - 15.7, 11.4635 + 15.7});
  fit.sum_sq_mm2 = dataset_sum_of_squares(d, fit.params, replay);
  fit.converged = true;

  const OptimumProbe probe = probe_optimum(d, fit, replay);
  // Down: 1/4, 1/2 and 3/4 of the way to 0. Up: 10 standard errors (91.46),
  // then 1/4, 1/2 and 3/4 of the way to 100.
  EXPECT_EQ(probe.points, 7);
  EXPECT_TRUE(probe.moved) << "start " << fit.sum_sq_mm2 << ", best " << probe.best_sum_sq_mm2 << " mm^2";
  EXPECT_LT(probe.best.surface.kappa_jam, 6.0) << probe.note;
  EXPECT_GT(probe.best.surface.kappa_jam, 2.0) << probe.note;
}

TEST(OptimumProbe, StaysAtAnOptimumWithNothingBetterNearby) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"jammed-sweep"}, true);
  LeastSquaresOptions options;
  options.replay.threads = 2;
  const LeastSquaresResult at_truth = fit_least_squares(d, truth(), mass_only(), options);
  const OptimumProbe probe = probe_optimum(d, at_truth, options.replay);
  EXPECT_FALSE(probe.moved) << probe.note;
  EXPECT_EQ(probe.best.surface.mass_kg, at_truth.params.surface.mass_kg);
  EXPECT_TRUE(probe.note.empty());
}

// The probe's replays stop once their cost passes what it could take: a
// bound above the sum gives the sum itself; one below it stops after the
// first session (the sessions run one after another) with a value above
// the bound and no more than the sum.
TEST(OptimumProbe, AReplayStopsOnceItsCostPassesTheBound) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"mixed-1", "unjammed-sweep"}, true);
  ReplayOptions replay = fitting_replay({});
  ReplayTally whole, cut;
  replay.tally = &whole;
  const double sum = dataset_sum_of_squares(d, truth(), replay);
  ASSERT_TRUE(std::isfinite(sum));
  EXPECT_EQ(whole.replays(), 2);
  replay.tally = nullptr;
  EXPECT_EQ(dataset_sum_of_squares(d, truth(), replay, 1, 1.001 * sum), sum);
  replay.tally = &cut;
  const double bounded = dataset_sum_of_squares(d, truth(), replay, 1, 0.1 * sum);
  EXPECT_GT(bounded, 0.1 * sum);
  EXPECT_LE(bounded, sum * (1.0 + 1e-9));
  EXPECT_EQ(cut.replays(), 1) << "the second session is not replayed";
}

}  // namespace
}  // namespace hj
