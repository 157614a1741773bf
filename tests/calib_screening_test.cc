// Screening (calib/screening.h) in the diagnosis, on the cheap sessions of
// demo-bending as calib_diagnose_test.cc: the effect the data have
// (bending) is refitted, effects the data do not have are screened out
// without a refit, and the verdict is the one the exhaustive path reaches.
#include <gtest/gtest.h>

#include <filesystem>

#include "calib/diagnosis.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

Dataset cheap_bending() {
  return select_sessions(read_dataset(fs::path(HJ_SHARED_DIR) / "data/sessions/demo-bending"),
                         {"unjammed-sweep", "mixed-1", "mixed-2"}, true);
}

DiagnoseOptions options(bool screening) {
  DiagnoseOptions o;
  o.candidates = {"bending", "sensor_tilt"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  o.screening = screening;
  return o;
}

const CandidateFit& find(const Diagnosis& d, const std::string& effect) {
  for (const auto& c : d.ranking)
    if (c.added == effect) return c;
  throw std::out_of_range("no candidate " + effect);
}

TEST(Screening, KeepsBendingScreensOutTheRestSameVerdict) {
  const Dataset d = cheap_bending();
  const Diagnosis screened = diagnose(d, ModelParams{}, options(true));
  ASSERT_EQ(screened.ranking.size(), 2u) << ::testing::PrintToString(screened.skipped);
  const CandidateFit& bending = find(screened, "bending");
  EXPECT_FALSE(bending.screened_out) << bending.screening_note;
  EXPECT_TRUE(bending.significant);
  EXPECT_EQ(screened.ranking[0].added, "bending");
  int screened_out = 0;
  for (const auto& c : screened.ranking)
    if (c.screened_out) {
      ++screened_out;
      EXPECT_FALSE(c.significant) << c.added;
      EXPECT_FALSE(c.screening_note.empty()) << c.added;
      // The prediction is a least-squares step from the baseline: no worse.
      EXPECT_LE(c.fit.rmse_mm, screened.baseline.joint.rmse_mm + 1e-9) << c.added;
    }
  EXPECT_GE(screened_out, 1);

  const Diagnosis exhaustive = diagnose(d, ModelParams{}, options(false));
  for (const auto& c : exhaustive.ranking) EXPECT_FALSE(c.screened_out) << c.added;
  EXPECT_EQ(screened.verdict, exhaustive.verdict);
  EXPECT_EQ(screened.verdict, std::vector<std::string>{"bending"});
  // The refitted candidate is the same fit either way.
  EXPECT_NEAR(bending.fit.rmse_mm, find(exhaustive, "bending").fit.rmse_mm, 1e-9);
}

}  // namespace
}  // namespace hj
