// The render loop's calibration on the fly (RENDER_CORRECTION_MODEL, BOTH):
// each iteration's run (its plan from rest and its capture) added to a
// dataset, the device model refitted on it between iterations by the
// library (calib/on_the_fly.h), and the result as the proto reports it.
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

  // Adds the run to the dataset and refits the model on every run so far.
  // @throws std::invalid_argument, std::runtime_error (a fit that fails),
  //         SettleInterrupted (cancelled).
  void add_run_and_fit(int iteration, const std::vector<Action>& actions, const SessionGrid& grid,
                       const Eigen::MatrixXd& frame_mm, hapticjam::v1::FittedModel* out);

  // The camera the model has found (sensor_tilt, else none), as a plane to
  // take out of the captures.
  CameraPlane camera() const;

 private:
  SessionDevice device_;
  OnTheFlyOptions options_;
  Dataset runs_;
  ModelParams model_;
};

// The fit as reported in the stream.
void fitted_model_to_proto(const OnTheFlyFit& fit, hapticjam::v1::FittedModel* out);

}  // namespace hj::server
