// Measurement effects (EffectInfo::measurement_only, e.g. sensor_tilt)
// change what the camera reports, not the surface: a dataset replayed once
// gives the sum of squares at any of their values. A scan over a camera
// tilt replayed demo-bending 41 times for the same surfaces (effect_scan.h).
#pragma once

#include <string>
#include <vector>

#include "calib/residuals.h"
#include "model/mesh.h"

namespace hj {

// True if the registry marks `effect` measurement-only.
// @throws std::invalid_argument for an unknown effect.
bool is_measurement_only(const std::string& effect);

// `params` with its measurement-only effects switched off: the same
// simulated surfaces.
ModelParams without_measurement_effects(ModelParams params);

// Every capture of a dataset as simulated before the camera sees it.
class CameraFreeReplay {
 public:
  // Replays the dataset (cold, on options.threads) with `params`'
  // measurement-only effects switched off. A replay that fails (no
  // equilibrium) is not an error here: every sum_of_squares() is then
  // infinite, as dataset_sum_of_squares() says. SettleInterrupted is let
  // through.
  CameraFreeReplay(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options);

  bool replayed() const { return replayed_; }

  // dataset_sum_of_squares(dataset, params, options), bit for bit, from the
  // replay: params' measurement effects applied to its captures in params'
  // order, as replay_session() applies them.
  // @throws std::invalid_argument if params simulates other surfaces (its
  //         physical effects or values differ from the constructor's).
  double sum_of_squares(const ModelParams& params) const;

 private:
  // What the camera needs of each session, made once for every point.
  struct SessionView {
    Mesh mesh;
    Eigen::VectorXd x_mm, y_mm;  // the sample grid (sample_x_mm, sample_y_mm)
    std::vector<PredictedCapture> captures;
  };
  const Dataset& dataset_;
  ModelParams physical_;
  bool replayed_ = false;
  std::vector<SessionView> sessions_;  // by session
};

}  // namespace hj
