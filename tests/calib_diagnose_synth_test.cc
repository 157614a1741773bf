// The diagnosis is not a special case for the shared datasets: on a tiny
// dataset synthesised here (3 x 4 array, two short sessions, the simulated
// camera's 1 mm noise) with the camera tilted and offset (sensor_tilt), the
// same code that finds bending in demo-bending chooses sensor_tilt among
// three candidates and fits its tilt and offset; on the same sessions
// without the effect it chooses nothing. scripts/synth_effects.sh runs the
// whole matrix (every effect, combinations) on demo-baseline's sessions.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/diagnosis.h"
#include "calib/synthesize.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kTiltX = 15.0, kTiltY = -10.0, kOffset = 1.5;  // mrad, mrad, mm

Dataset synthetic(const fs::path& root, bool tilted) {
  ModelParams truth = testing_support::true_tiny_baseline();
  if (tilted) {
    truth.effects = {"sensor_tilt"};
    truth.effect_parameters["sensor_tilt"] = {{"tilt_x_mrad", kTiltX}, {"tilt_y_mrad", kTiltY}, {"offset_mm", kOffset}};
  }
  return testing_support::synthesize_tiny(root, truth);
}

DiagnoseOptions three_candidates() {
  DiagnoseOptions o;
  o.candidates = {"sensor_tilt", "pressure_offset", "jam_contraction"};
  o.max_effects = 2;
  o.fit.least_squares.max_iterations = 10;
  return o;
}

// A candidate extends the model it is judged against, so its refit can
// always match it: none of the first round's refits ends above the
// baseline (to the least squares' convergence).
void expect_no_refit_above_the_baseline(const Diagnosis& result) {
  for (const CandidateFit& c : result.ranking) {
    if (c.screened_out) continue;
    EXPECT_LE(c.fit.rmse_mm, 1.001 * result.baseline.joint.rmse_mm) << c.added;
  }
}

TEST(CalibDiagnoseSynth, FindsTheCameraTiltAndFitsIt) {
  testing_support::ScratchDir scratch("tilt");
  const Dataset d = synthetic(scratch.path, true);
  const Diagnosis result = diagnose(d, ModelParams{}, three_candidates());
  ASSERT_TRUE(result.skipped.empty()) << ::testing::PrintToString(result.skipped);
  ASSERT_FALSE(result.ranking.empty());
  EXPECT_EQ(result.ranking[0].added, "sensor_tilt");
  expect_no_refit_above_the_baseline(result);
  ASSERT_EQ(result.verdict, std::vector<std::string>{"sensor_tilt"});
  // Each within three of the fit's own standard errors, and those small:
  // about 0.2-0.4 mrad for the tilts and 0.3 mm for the offset, which
  // trades off against the mass (both lift the sagging rest state).
  const LeastSquaresResult& fit = result.ranking[0].fit;
  const std::pair<const char*, double> truth[] = {
      {"sensor_tilt.tilt_x_mrad", kTiltX}, {"sensor_tilt.tilt_y_mrad", kTiltY}, {"sensor_tilt.offset_mm", kOffset}};
  for (const auto& [name, value] : truth) {
    const ParameterEstimate* e = nullptr;
    for (const auto& estimate : fit.estimates)
      if (estimate.parameter.qualified_name() == name) e = &estimate;
    ASSERT_NE(e, nullptr) << name;
    EXPECT_LT(e->std_error, 0.5) << name;
    EXPECT_NEAR(e->value, value, 3.0 * e->std_error) << name;
    EXPECT_EQ(result.final_params.effect_parameters.at("sensor_tilt").at(name + std::string("sensor_tilt.").size()),
              e->value);
  }
  // The chosen fit converged before the next round was judged against it,
  // or no next round was needed.
  for (const std::string& note : result.notes)
    EXPECT_EQ(note.find("did not converge"), std::string::npos) << note;
  // With the effect the fit is down at the camera's noise floor.
  EXPECT_GT(result.baseline.joint.rmse_mm, 1.3 * result.noise_floor_mm);
  EXPECT_LT(result.ladder.back().rmse_mm, 1.05 * result.noise_floor_mm);
}

TEST(CalibDiagnoseSynth, ChoosesNothingWithoutAnEffect) {
  testing_support::ScratchDir scratch("control");
  const Dataset d = synthetic(scratch.path, false);
  const Diagnosis result = diagnose(d, ModelParams{}, three_candidates());
  EXPECT_TRUE(result.skipped.empty()) << ::testing::PrintToString(result.skipped);
  EXPECT_EQ(result.ranking.size(), 3u);
  EXPECT_TRUE(result.verdict.empty()) << ::testing::PrintToString(result.verdict);
  for (const auto& c : result.ranking) EXPECT_FALSE(c.significant) << c.added;
  expect_no_refit_above_the_baseline(result);
  EXPECT_LT(result.baseline.joint.rmse_mm, 1.05 * result.noise_floor_mm);
}

// One candidate, fits capped at one iteration (the paper's start is far from
// this optimum) and not fitted on: a baseline cut short.
DiagnoseOptions cut_short() {
  DiagnoseOptions o = three_candidates();
  o.candidates = {"jam_contraction"};
  o.fit.least_squares.max_iterations = 1;
  o.max_continuations = 0;
  return o;
}

// A baseline cut short by the iteration cap is fitted on before anything
// is judged against it; one that still has not converged is named.
TEST(CalibDiagnoseSynth, TheBaselineIsFittedOnUntilItConverges) {
  testing_support::ScratchDir scratch("converge");
  const Dataset d = synthetic(scratch.path, false);
  DiagnoseOptions o = cut_short();
  // The continuation alone: an optimum probe also moves a fit stopped at its
  // cap (optimum_probe.h), and here takes it to convergence by itself.
  o.fit.probe_rounds = 0;
  const Diagnosis cut = diagnose(d, ModelParams{}, o);
  ASSERT_EQ(cut.notes.size(), 1u) << ::testing::PrintToString(cut.notes);
  EXPECT_NE(cut.notes[0].find("baseline: the fit did not converge within 1 iterations"), std::string::npos)
      << cut.notes[0];
  o.max_continuations = 30;
  const Diagnosis finished = diagnose(d, ModelParams{}, o);
  EXPECT_TRUE(finished.notes.empty()) << ::testing::PrintToString(finished.notes);
  EXPECT_TRUE(finished.baseline.joint.converged);
  EXPECT_LT(finished.baseline.joint.sum_sq_mm2, cut.baseline.joint.sum_sq_mm2);
  EXPECT_LT(finished.baseline.joint.rmse_mm, 1.05 * finished.noise_floor_mm);
}

// A fit cut off by its iteration cap while still descending is probed like
// a converged one, and restarted from the better point the probe finds.
TEST(CalibDiagnoseSynth, AFitStoppedAtItsCapIsProbedAndRestarted) {
  testing_support::ScratchDir scratch("capped-probe");
  const Dataset d = synthetic(scratch.path, false);
  DiagnoseOptions o = cut_short();
  const Diagnosis probed = diagnose(d, ModelParams{}, o);
  EXPECT_TRUE(std::any_of(probed.notes.begin(), probed.notes.end(), [](const std::string& note) {
    return note.find("stopped at its iteration cap short of a better point") != std::string::npos;
  })) << ::testing::PrintToString(probed.notes);
  o.fit.probe_rounds = 0;
  const Diagnosis cut = diagnose(d, ModelParams{}, o);
  EXPECT_LT(probed.baseline.joint.sum_sq_mm2, cut.baseline.joint.sum_sq_mm2);
  EXPECT_LT(probed.baseline.joint.rmse_mm, 1.05 * probed.noise_floor_mm);
}

// The loophole the control dataset found: a sample the predicted surface
// does not cover (here, outside the array) is predicted at the clamp level,
// 0 mm, so its residual is -measured, not 0 (a perfect fit).
TEST(CalibDiagnoseSynth, UncoveredSamplesArePredictedAtTheClampLevel) {
  MeasuredSession m;
  m.session.name = "edge";
  m.session.device = {3, 4, 38.0, 3.45};
  m.session.grid = {5, 1, -20.0, 57.0, 10.0, 2.0};  // x = -20, -10, 0, 10, 20 mm
  SessionStep capture;
  capture.kind = SessionStep::Kind::kCapture;
  capture.frame = "frames/000.csv";
  m.session.steps = {capture};
  MeasuredCapture c;
  c.frame = capture.frame;
  c.heights_mm = Eigen::MatrixXd::Constant(1, 5, 3.0);
  c.heights_mm(0, 4) = NAN;  // missing: not a residual at all
  c.jammed.assign(12, false);
  m.captures = {c};
  ModelParams params = testing_support::true_tiny_baseline();
  const Eigen::VectorXd r = session_residuals(m, params, fitting_replay({}));
  ASSERT_EQ(r.size(), 4);
  EXPECT_EQ(r[0], -3.0);  // outside the array
  EXPECT_EQ(r[1], -3.0);
  // On the clamped edge and inside, the surface is predicted (it sags at rest).
  EXPECT_NEAR(r[2], -3.0, 1e-9);
  EXPECT_LT(r[3], -3.0);
}

}  // namespace
}  // namespace hj
