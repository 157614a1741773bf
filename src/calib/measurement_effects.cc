#include "calib/measurement_effects.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>

#include "model/mesh.h"

namespace hj {

bool is_measurement_only(const std::string& effect) {
  return EffectRegistry::instance().get(effect).measurement_only;
}

ModelParams without_measurement_effects(ModelParams params) {
  std::vector<std::string> kept;
  for (const std::string& effect : params.effects)
    if (is_measurement_only(effect))
      params.effect_parameters.erase(effect);
    else
      kept.push_back(effect);
  params.effects = std::move(kept);
  return params;
}

CameraFreeReplay::CameraFreeReplay(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options)
    : dataset_(dataset), segments_(options.segments), physical_(without_measurement_effects(params)) {
  try {
    Evaluation replay = evaluate_dataset(dataset, physical_, options);
    for (SessionEvaluation& session : replay.sessions) captures_.push_back(std::move(session.predicted));
    replayed_ = true;
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    captures_.clear();  // no equilibrium somewhere: every point fails
  }
}

double CameraFreeReplay::sum_of_squares(const ModelParams& params) const {
  if (model_params_json(without_measurement_effects(params)) != model_params_json(physical_))
    throw std::invalid_argument("CameraFreeReplay: the parameters simulate other surfaces than the replay's");
  if (!replayed_) return std::numeric_limits<double>::infinity();
  const auto effects = make_effects(params.effects, params.effect_parameters);
  double sum = 0.0;
  for (size_t s = 0; s < dataset_.sessions.size(); ++s) {
    const MeasuredSession& measured = dataset_.sessions[s];
    const Mesh mesh(measured.session.device.geometry(segments_));
    const Eigen::VectorXd x_mm = sample_x_mm(measured.session.grid), y_mm = sample_y_mm(measured.session.grid);
    std::vector<PredictedCapture> seen = captures_[s];
    for (PredictedCapture& capture : seen)
      for (const auto& effect : effects) effect->adjust_measurement(mesh, x_mm, y_mm, capture.heights_mm);
    sum += capture_residuals(measured, seen).squaredNorm();  // in session order, as dataset_sum_of_squares()
  }
  return sum;
}

}  // namespace hj
