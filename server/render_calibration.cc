#include "render_calibration.h"

#include <algorithm>

#include "calib/probe.h"
#include "fitted_parameter_proto.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

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
  return probe_for_plan(geometry_, model_, options_.replay, from, plan, goal_top_mm);
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
