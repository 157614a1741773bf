// Calibration on the fly (calib/on_the_fly.h): runs from rest as sessions,
// and the device model refitted on them with the effects the selection adds.
// The runs' frames are the model's own (a device with stiffening and a
// tilted camera, replayed), seen through a 1 mm camera.
#include "calib/on_the_fly.h"
#include "calib/probe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "calib/replay.h"
#include "calib/synthesize.h"

namespace hj {
namespace {

const ArrayGeometry kGeometry{3, 4, 0.038, 4};

SessionDevice device() { return {3, 4, 38.0, 3.45}; }

SessionGrid grid() {
  SessionGrid g;
  g.nx = 77, g.ny = 58, g.dx_mm = 2.0, g.dy_mm = 2.0;
  return g;
}

ModelParams baseline() {
  ModelParams p;
  p.surface = SurfaceParameters::paper_defaults(kGeometry);
  return p;
}

ModelParams tilted_stiff_device() {
  ModelParams p = with_effects(baseline(), {"stiffening", "sensor_tilt"});
  p.effect_parameters["stiffening"]["beta"] = 30.0;
  p.effect_parameters["sensor_tilt"]["tilt_x_mrad"] = 15.0;
  p.effect_parameters["sensor_tilt"]["tilt_y_mrad"] = -10.0;
  return p;
}

Action pressure(double pa) { return Action::set_pressure(pa); }

// What the device's camera shows after `actions` from rest: the model's
// capture, with noise.
Eigen::MatrixXd captured(const ModelParams& device_model, const std::vector<Action>& actions, std::uint64_t seed) {
  const MeasuredSession blank = run_session("blank", device(), grid(), actions,
                                            Eigen::MatrixXd::Zero(grid().ny, grid().nx));
  ReplayOptions replay;
  const auto predicted = replay_session(blank.session, kGeometry.segments, device_model.surface,
                                        simulator_options(device_model, replay));
  std::mt19937_64 rng(seed);
  SynthOptions camera;
  camera.drop_fraction = 0.0;
  return add_camera_noise(predicted.back().heights_mm, camera, rng);
}

Dataset runs(const ModelParams& device_model) {
  const std::vector<std::vector<Action>> plans = {
      {pressure(1200), Action::jam(0, 1), Action::pin(1, 1), pressure(2400), Action::jam(1, 2), pressure(3000)},
      {pressure(1500), Action::jam(1, 1), pressure(2800), Action::pin(1, 3)},
  };
  Dataset out;
  for (size_t i = 0; i < plans.size(); ++i)
    out.sessions.push_back(run_session("run-" + std::to_string(i + 1), device(), grid(), plans[i],
                                       captured(device_model, plans[i], 7 + i)));
  return out;
}

TEST(OnTheFly, ARunIsASessionFromRestWithOneCaptureAfterItsActions) {
  const MeasuredSession s = run_session("run-1", device(), grid(), {pressure(1500), Action::jam(0, 1)},
                                        Eigen::MatrixXd::Constant(grid().ny, grid().nx, 2.0));
  ASSERT_EQ(s.session.steps.size(), 3u);
  EXPECT_EQ(s.session.steps.back().kind, SessionStep::Kind::kCapture);
  ASSERT_EQ(s.captures.size(), 1u);
  EXPECT_DOUBLE_EQ(s.captures[0].pressure_pa, 1500.0);
  EXPECT_EQ(s.captures[0].jammed_count(), 1);
  EXPECT_TRUE(s.captures[0].jammed[1]);
}

TEST(OnTheFly, AFrameOfAnotherShapeIsRefusedNamingTheRun) {
  try {
    run_session("run-3", device(), grid(), {}, Eigen::MatrixXd::Zero(5, 5));
    FAIL() << "accepted a 5 x 5 frame";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("run-3"), std::string::npos) << e.what();
  }
}

TEST(OnTheFly, AProbeIsASessionWithACaptureAtRestAndAfterEachPressure) {
  const std::vector<Action> probe = probe_actions(500.0, 2000.0, 4);
  ASSERT_EQ(probe.size(), 4u);
  EXPECT_DOUBLE_EQ(probe.front().pressure_pa, 500.0);
  EXPECT_DOUBLE_EQ(probe[1].pressure_pa, 1000.0);
  EXPECT_DOUBLE_EQ(probe.back().pressure_pa, 2000.0);
  std::vector<RunCapture> captures;
  for (size_t k = 0; k <= probe.size(); ++k)
    captures.push_back({k, Eigen::MatrixXd::Constant(grid().ny, grid().nx, double(k))});
  const MeasuredSession s = captured_session("probe", device(), grid(), probe, captures);
  ASSERT_EQ(s.captures.size(), 5u);
  EXPECT_DOUBLE_EQ(s.captures[0].pressure_pa, 0.0);
  EXPECT_DOUBLE_EQ(s.captures[4].pressure_pa, 2000.0);
  EXPECT_DOUBLE_EQ(s.captures[3].heights_mm(0, 0), 3.0);
  EXPECT_EQ(s.captures[2].jammed_count(), 0);
}

TEST(OnTheFly, ACaptureOutOfOrderOrPastTheActionsIsRefusedNamingTheRun) {
  const Eigen::MatrixXd frame = Eigen::MatrixXd::Zero(grid().ny, grid().nx);
  const std::vector<Action> probe = probe_actions(500.0, 1000.0, 2);
  for (const std::vector<RunCapture>& bad : {std::vector<RunCapture>{{2, frame}, {1, frame}},
                                             std::vector<RunCapture>{{3, frame}}}) {
    try {
      captured_session("probe-2", device(), grid(), probe, bad);
      ADD_FAILURE() << "accepted a capture after " << bad.back().after_actions << " actions";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("probe-2"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(probe_actions(0.0, 1000.0, 3), std::invalid_argument);
  EXPECT_THROW(probe_actions(1000.0, 500.0, 3), std::invalid_argument);
  EXPECT_THROW(probe_actions(500.0, 1000.0, 0), std::invalid_argument);
}

TEST(OnTheFly, ACandidateThatIsPartOfTheBaselineIsRefused) {
  OnTheFlyOptions options;
  options.candidates = {"springs"};
  EXPECT_THROW(options.validate(), std::invalid_argument);
}

// The tilt is a measurement effect found from the captures, and the
// stiffening a physical one: both added, the tilt near the truth, the fit
// down to the camera's noise (1 mm plus its rounding).
TEST(OnTheFly, FindsTheCameraTiltAndTheStiffeningOfTheDevice) {
  const Dataset dataset = runs(tilted_stiff_device());
  const OnTheFlyFit fit = calibrate_on_the_fly(dataset, baseline(), {});
  const auto has = [&](const std::string& e) {
    return std::find(fit.added.begin(), fit.added.end(), e) != fit.added.end();
  };
  EXPECT_TRUE(has("sensor_tilt")) << ::testing::PrintToString(fit.notes);
  EXPECT_TRUE(has("stiffening")) << ::testing::PrintToString(fit.notes);
  ASSERT_TRUE(fit.params.effect_parameters.count("sensor_tilt"));
  EXPECT_NEAR(fit.params.effect_parameters.at("sensor_tilt").at("tilt_x_mrad"), 15.0, 1.0);
  EXPECT_NEAR(fit.params.effect_parameters.at("sensor_tilt").at("tilt_y_mrad"), -10.0, 1.0);
  EXPECT_LT(fit.rmse_mm, 1.2);
  EXPECT_EQ(fit.captures, 2);
  EXPECT_GT(fit.replays, 0);
}

// The probe alone (the free membrane at four pressures, no jam or pin)
// shows the stiffening and the tilt: the dome's height bends with pressure.
TEST(OnTheFly, FindsTheCameraTiltAndTheStiffeningOfTheDeviceOnAProbe) {
  const std::vector<Action> probe = probe_actions(470.0, 3000.0, 4);
  std::vector<RunCapture> captures;
  for (size_t k = 0; k <= probe.size(); ++k)
    captures.push_back({k, captured(tilted_stiff_device(), {probe.begin(), probe.begin() + long(k)}, 11 + k)});
  Dataset dataset;
  dataset.sessions.push_back(captured_session("probe", device(), grid(), probe, captures));
  const OnTheFlyFit fit = calibrate_on_the_fly(dataset, baseline(), {});
  for (const char* effect : {"sensor_tilt", "stiffening"})
    EXPECT_NE(std::find(fit.added.begin(), fit.added.end(), effect), fit.added.end())
        << effect << ": " << ::testing::PrintToString(fit.notes);
  ASSERT_TRUE(fit.params.effect_parameters.count("sensor_tilt"));
  EXPECT_NEAR(fit.params.effect_parameters.at("sensor_tilt").at("tilt_x_mrad"), 15.0, 1.0);
  EXPECT_NEAR(fit.params.effect_parameters.at("sensor_tilt").at("tilt_y_mrad"), -10.0, 1.0);
  EXPECT_LT(fit.rmse_mm, 1.2) << ::testing::PrintToString(fit.notes) << fit.params.surface.spring_k << " beta "
                              << fit.params.effect_parameters.at("stiffening").at("beta");
  EXPECT_EQ(fit.captures, 5);
}

// On a device the baseline describes, nothing is added.
TEST(OnTheFly, AddsNothingToAModelThatExplainsTheRuns) {
  const Dataset dataset = runs(baseline());
  const OnTheFlyFit fit = calibrate_on_the_fly(dataset, baseline(), {});
  EXPECT_TRUE(fit.added.empty()) << ::testing::PrintToString(fit.notes);
  EXPECT_NEAR(fit.params.surface.spring_k, baseline().surface.spring_k, 0.05 * baseline().surface.spring_k);
}

}  // namespace
}  // namespace hj
