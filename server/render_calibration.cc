#include "render_calibration.h"

#include <algorithm>

#include "calib/residuals.h"
#include "fitted_parameter_proto.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

namespace {

// Pressures of the probe: enough to tell a stiffening (the dome's height
// against pressure bends) from a softer spring, few enough to be cheap.
constexpr int kProbeLevels = 4;

// The highest pressure at which `plan` jams or pins (its highest pressure if
// it does neither): past it a plan's pressure only moves its free cells,
// and a free 6 x 8 dome there (3.45 kPa) is one the planner's model, fitted
// to a stiffening device, can fail to settle, where the fit's time goes.
double shaping_pressure_pa(const std::vector<Action>& plan) {
  double pressure = 0.0, top = 0.0, shaping = 0.0;
  for (const Action& a : plan) {
    if (a.op == Action::Op::kSetPressure)
      pressure = a.pressure_pa, top = std::max(top, pressure);
    else if (a.op == Action::Op::kJam || a.op == Action::Op::kPin)
      shaping = std::max(shaping, pressure);
  }
  return shaping > 0.0 ? shaping : top;
}

// The probe covers the heights the goal asks for, with this margin: a
// probe far above them (a free 6 x 8 dome at 3 kPa, 150 mm, for a goal of
// 84 mm) is where the baseline model is furthest off (39 mm RMSE on the
// stiffening device), every candidate passes against it, and the fit of
// all of them together is most of the render's fitting time.
constexpr double kProbeHeightMargin = 1.5;

// The first of `steps` pressures from `from_pa` to `to_pa` at which the free
// membrane of `model` domes to `height_mm` (to_pa if none does, or if a
// settle fails).
double pressure_reaching(const ArrayGeometry& geometry, const ModelParams& model, const ReplayOptions& replay,
                         double from_pa, double to_pa, double height_mm) {
  constexpr int kSteps = 8;
  Simulator simulator(geometry, model.surface, simulator_options(model, replay));
  try {
    for (int k = 0; k <= kSteps; ++k) {
      const double pressure = from_pa + (to_pa - from_pa) * k / kSteps;
      simulator.apply(Action::set_pressure(pressure));
      if (point_heights(simulator.mesh(), simulator.state().x).maxCoeff() * 1000.0 >= height_mm) return pressure;
    }
  } catch (const NoEquilibrium&) {
  }
  return to_pa;
}

}  // namespace

RenderCalibration::RenderCalibration(const ArrayGeometry& geometry, const ModelParams& start, int threads,
                                     std::function<bool()> cancelled)
    : geometry_(geometry), model_(start) {
  device_.rows = geometry.rows, device_.cols = geometry.cols;
  device_.cell_size_mm = geometry.cell_size_m * 1000.0;
  device_.max_pressure_kpa = start.surface.max_pressure_pa / 1000.0;
  options_.replay.segments = geometry.segments;  // the planner's mesh: the model it plans with
  options_.replay.threads = threads;
  options_.replay.interrupted = std::move(cancelled);
  // The probe's settles are of the free membrane, which the static solver
  // settles from the state before; a fit's point where it cannot is a bad
  // point, and the explicit fallback would spend its steps to learn that.
  options_.replay.fallbacks = false;
  // spring_k and a stiffening's beta trade along a long valley on a probe up
  // to 2 kPa: on a 6 x 8 one, 5 iterations end at spring_k 106, beta 12
  // (RMSE 2.1 mm), 50 at 65, 28 (1.14 mm; truth 64.5, 30). A probe's
  // replay is a few free settles, so the iterations are cheap.
  options_.max_iterations = 50;
}

std::vector<Action> RenderCalibration::probe(double levelling_margin, const std::vector<Action>& plan,
                                             double goal_top_mm) const {
  const double from = levelling_margin * model_.surface.levelling_pressure_pa(Mesh(geometry_));
  const double limit = model_.surface.max_pressure_pa;
  const double shaping = std::min(limit, std::max(shaping_pressure_pa(plan), 2.0 * from));
  const double reach =
      pressure_reaching(geometry_, model_, options_.replay, from, shaping, kProbeHeightMargin * goal_top_mm);
  const double top = std::min(shaping, std::max(reach, 2.0 * from));
  return probe_actions(std::min(from, top), top, kProbeLevels);
}

void RenderCalibration::fit_probe(const std::vector<Action>& actions, const SessionGrid& grid,
                                  const std::vector<Eigen::MatrixXd>& frames, v1::FittedModel* out) {
  std::vector<RunCapture> captures;
  for (size_t k = 0; k < frames.size(); ++k) captures.push_back({k, frames[k]});
  Dataset probe;
  probe.dir = "render";
  probe.sessions.push_back(captured_session("probe", device_, grid, actions, captures));
  const OnTheFlyFit fit = calibrate_on_the_fly(probe, model_, options_);
  model_ = fit.params;
  fitted_ = true;
  fitted_model_to_proto(fit, out);
  for (size_t k = 0; k + 1 < frames.size(); ++k) out->add_probe_pressures_kpa(actions[k].pressure_pa / 1000.0);
}

CameraPlane RenderCalibration::camera() const {
  CameraPlane plane;
  const auto tilt = model_.effect_parameters.find("sensor_tilt");
  if (std::find(model_.effects.begin(), model_.effects.end(), "sensor_tilt") == model_.effects.end() ||
      tilt == model_.effect_parameters.end())
    return plane;
  plane.tilt_x_mrad = tilt->second.at("tilt_x_mrad");
  plane.tilt_y_mrad = tilt->second.at("tilt_y_mrad");
  plane.offset_mm = tilt->second.at("offset_mm");
  return plane;
}

void fitted_model_to_proto(const OnTheFlyFit& fit, v1::FittedModel* out) {
  for (const ParameterEstimate& e : fit.estimates) estimate_to_proto(e, out->add_parameters());
  for (const auto& e : fit.params.effects) out->add_effects(e);
  for (const auto& e : fit.added) out->add_added(e);
  out->set_rmse_mm(fit.rmse_mm);
  out->set_captures(fit.captures);
  out->set_samples(fit.samples);
  out->set_replays(fit.replays);
  for (const auto& n : fit.notes) out->add_notes(n);
}

}  // namespace hj::server
