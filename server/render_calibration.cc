#include "render_calibration.h"

#include <algorithm>

#include "fitted_parameter_proto.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

RenderCalibration::RenderCalibration(const ArrayGeometry& geometry, const ModelParams& start, int threads,
                                     std::function<bool()> cancelled)
    : model_(start) {
  device_.rows = geometry.rows, device_.cols = geometry.cols;
  device_.cell_size_mm = geometry.cell_size_m * 1000.0;
  device_.max_pressure_kpa = start.surface.max_pressure_pa / 1000.0;
  options_.replay.segments = geometry.segments;  // the planner's mesh: the model it plans with
  options_.replay.threads = threads;
  options_.replay.interrupted = std::move(cancelled);
  runs_.dir = "render";
}

void RenderCalibration::add_run_and_fit(int iteration, const std::vector<Action>& actions, const SessionGrid& grid,
                                        const Eigen::MatrixXd& frame_mm, v1::FittedModel* out) {
  runs_.sessions.push_back(run_session("iteration-" + std::to_string(iteration), device_, grid, actions, frame_mm));
  const OnTheFlyFit fit = calibrate_on_the_fly(runs_, model_, options_);
  model_ = fit.params;
  fitted_model_to_proto(fit, out);
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
