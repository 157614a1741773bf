// Screening a closed loop's corrected plan (metrics/correction_screen.h):
// the expected outcome is the plan's prediction moved by the last run's
// misfit, a plan expected clearly worse than the best run does not pass, and
// halving a correction takes the targets halfway back; a refused rise of
// pressure limits later plans.
#include "metrics/correction_screen.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace hj {
namespace {

TEST(CorrectionScreen, TheExpectedOutcomeIsThePredictionMovedByTheLastMisfit) {
  Eigen::MatrixXd next(2, 2), measured(2, 2), predicted(2, 2);
  next << 10, 20, 30, 40;
  measured << 9, 21, NAN, 40;
  predicted << 10, 20, 30, 38;
  const Eigen::MatrixXd expected = expected_outcome(next, measured, predicted);
  EXPECT_DOUBLE_EQ(expected(0, 0), 9.0);
  EXPECT_DOUBLE_EQ(expected(0, 1), 21.0);
  EXPECT_TRUE(std::isnan(expected(1, 0)));  // not seen last time: no expectation there
  EXPECT_DOUBLE_EQ(expected(1, 1), 42.0);
}

TEST(CorrectionScreen, APlanExpectedClearlyWorseThanTheBestDoesNotPass) {
  EXPECT_TRUE(passes_screen(1.9, 2.0));
  EXPECT_TRUE(passes_screen(2.4, 2.0));    // within the noise of one capture
  EXPECT_FALSE(passes_screen(52.0, 4.1));  // a plan that ends in the jammed sag
  EXPECT_FALSE(passes_screen(NAN, 2.0));
  EXPECT_TRUE(passes_screen(2.0, 2.0, CorrectionScreenOptions{1.0, 3}));
  EXPECT_FALSE(passes_screen(2.01, 2.0, CorrectionScreenOptions{1.0, 3}));
}

TEST(CorrectionScreen, HalvingACorrectionTakesTheTargetsHalfwayBack) {
  Eigen::MatrixXd previous(1, 3), corrected(1, 3);
  previous << 0, 10, -4;
  corrected << 2, 10, 4;
  const Eigen::MatrixXd halved = halved_correction(previous, corrected);
  EXPECT_DOUBLE_EQ(halved(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(halved(0, 1), 10.0);
  EXPECT_DOUBLE_EQ(halved(0, 2), 0.0);
}

TEST(CorrectionScreen, BadShapesAndOptionsAreNamed) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2, 2), b = Eigen::MatrixXd::Zero(2, 3);
  EXPECT_THROW(expected_outcome(a, b, b), std::invalid_argument);
  EXPECT_THROW(halved_correction(a, b), std::invalid_argument);
  EXPECT_THROW(passes_screen(1.0, NAN), std::invalid_argument);
  EXPECT_THROW(passes_screen(1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(passes_screen(1.0, 1.0, CorrectionScreenOptions{0.5, 3}), std::invalid_argument);
  EXPECT_THROW(passes_screen(1.0, 1.0, CorrectionScreenOptions{1.25, -1}), std::invalid_argument);
  try {
    halved_correction(a, b);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shapes differ, 2 x 2 and 2 x 3"), std::string::npos) << e.what();
  }
}

const std::vector<Action> kRun = {Action::set_pressure(500), Action::jam(0, 0), Action::set_pressure(1500),
                                  Action::jam(1, 1), Action::set_pressure(2500), Action::pin(1, 1)};

TEST(PressureLimit, ARefusedRiseOfPressureLimitsLaterPlansToThePressureBeforeIt) {
  EXPECT_DOUBLE_EQ(pressure_limit_after_refusal(kRun, 4, 900.0), 1500.0);
}

TEST(PressureLimit, ARefusedJamOrPinOrARefusalNearLevellingTeachesNoLimit) {
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(kRun, 3, 900.0)));  // a jam
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(kRun, 5, 900.0)));  // a pin
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(kRun, 2, 900.0)));  // from 500 Pa, below the floor
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(kRun, 0, 0.0)));    // nothing before it
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(kRun, 9, 0.0)));    // past the run
  const std::vector<Action> falling = {Action::set_pressure(2000), Action::set_pressure(1200)};
  EXPECT_TRUE(std::isinf(pressure_limit_after_refusal(falling, 1, 900.0)));  // a fall of pressure
}

}  // namespace
}  // namespace hj
