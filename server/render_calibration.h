// The render loop's calibration on the fly (RENDER_CORRECTION_MODEL, BOTH):
// a probe of the device (the free membrane raised through a few pressures,
// captured at rest and at each) as a dataset, the device model fitted on it
// by the library (calib/on_the_fly.h), and the result as the proto reports it.
#pragma once

#include <functional>
#include <string>

#include "calib/on_the_fly.h"
#include "hapticjam/v1/render_service.pb.h"
#include "metrics/height_error.h"
#include "model/mesh.h"

namespace hj::server {

class RenderCalibration {
 public:
  // `start`: the planner's model (the request's parameters and effects).
  RenderCalibration(const ArrayGeometry& geometry, const ModelParams& start, int threads,
                    std::function<bool()> cancelled);

  // The model to plan the next iteration with (the start until a fit).
  const ModelParams& model() const { return model_; }

  bool fitted() const { return fitted_; }

  // The probe's actions from rest after `plan` ran: from the render's
  // levelling margin up to the highest pressure at which the plan jams or
  // pins, or lower, where the model's free dome reaches 1.5 x
  // `goal_top_mm` (at least twice the first level, at most the array's limit).
  std::vector<Action> probe(double levelling_margin, const std::vector<Action>& plan, double goal_top_mm) const;

  // Fits the model on the probe's captures: frames[0] at rest, frames[k]
  // after actions[k - 1] (a probe the device cut short has fewer).
  // @throws std::invalid_argument, std::runtime_error (a fit that fails),
  //         SettleInterrupted (cancelled).
  void fit_probe(const std::vector<Action>& actions, const SessionGrid& grid, const std::vector<Eigen::MatrixXd>& frames,
                 hapticjam::v1::FittedModel* out);

  // The camera the model has found (sensor_tilt, else none), as a plane to
  // take out of the captures.
  CameraPlane camera() const;

 private:
  ArrayGeometry geometry_;
  SessionDevice device_;
  OnTheFlyOptions options_;
  ModelParams model_;
  bool fitted_ = false;
};

// The fit as reported in the stream.
void fitted_model_to_proto(const OnTheFlyFit& fit, hapticjam::v1::FittedModel* out);

}  // namespace hj::server
