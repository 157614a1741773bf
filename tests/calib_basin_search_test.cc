// Which refitted candidates diagnose searches for a better basin (a range
// search, an optimum probe, its earlier optimum; calib/selection.h): an
// unexplained one, unless a significant candidate of its round leaves far
// less misfit above the noise floor (DiagnoseOptions::search_excess_ratio).
#include <gtest/gtest.h>

#include <cmath>

#include "calib/selection.h"

namespace hj {
namespace {

constexpr double kFloorMm = 1.0;
constexpr long kSamples = 100000;

LeastSquaresResult fit_at(double rmse_mm) {
  LeastSquaresResult fit;
  fit.residual_count = kSamples;
  fit.free_parameters = 4;
  fit.rmse_mm = rmse_mm;
  fit.sum_sq_mm2 = rmse_mm * rmse_mm * kSamples;
  return fit;
}

CandidateFit candidate_at(double rmse_mm) {
  CandidateFit c;
  c.added = "bending";
  c.fit = fit_at(rmse_mm);
  return c;
}

struct Round {
  Dataset dataset;
  DiagnoseOptions options;
  DiagnoseProgress progress;
  Diagnosis out;
  Selection selection{dataset, options, progress, out, {}, fit_at(2.0), 2.0};
  Round() { out.noise_floor_mm = kFloorMm; }
};

TEST(BasinSearch, AnUnexplainedCandidateIsSearchedWhileNoneOfItsRoundIsFarAhead) {
  Round round;
  EXPECT_TRUE(worth_a_basin_search(round.selection, candidate_at(1.8)));
  round.selection.round_best_excess_mm2 = 1.5 * 1.5 - 1.0;  // a significant one at 1.5 mm
  EXPECT_TRUE(worth_a_basin_search(round.selection, candidate_at(1.8)))  // excess 2.24 against 1.25
      << "within search_excess_ratio (2) of the round's best excess";
}

TEST(BasinSearch, OneFarBehindASignificantCandidateOfItsRoundIsNot) {
  Round round;
  round.selection.round_best_excess_mm2 = 1.5 * 1.5 - 1.0;
  EXPECT_FALSE(worth_a_basin_search(round.selection, candidate_at(2.0)));  // excess 3 against 1.25
  round.options.search_excess_ratio = 0.0;                                 // 0: always searched
  EXPECT_TRUE(worth_a_basin_search(round.selection, candidate_at(2.0)));
}

TEST(BasinSearch, AnExplainedCandidateOrRoundIsNotSearched) {
  Round round;
  EXPECT_FALSE(worth_a_basin_search(round.selection, candidate_at(1.02)))  // within 5 % of the floor
      << "its local refit already explains the data";
  round.selection.round_explained = true;
  EXPECT_FALSE(worth_a_basin_search(round.selection, candidate_at(1.8)));
}

TEST(BasinSearch, FromAnEarlierOptimumOnlyResidualsThatAreTheSensorsNoiseAreEnough) {
  // 1.02 mm against a 1 mm floor is within the floor's tolerance, but over
  // 1e5 samples chi-square rejects it: a better basin may exist.
  Round round;
  EXPECT_TRUE(worth_a_basin_search(round.selection, candidate_at(1.02), true));
  EXPECT_FALSE(worth_a_basin_search(round.selection, candidate_at(1.0), true));  // chi-square p about 0.5
}

}  // namespace
}  // namespace hj
