#include "calib/measurement_effects.h"

#include <limits>
#include <stdexcept>

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
    : dataset_(dataset), physical_(without_measurement_effects(params)) {
  Evaluation replay;
  try {
    replay = evaluate_dataset(dataset, physical_, options);
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    return;  // no equilibrium somewhere: every point fails
  }
  for (size_t s = 0; s < dataset.sessions.size(); ++s) {
    const Session& session = dataset.sessions[s].session;
    sessions_.push_back({Mesh(session.device.geometry(options.segments)), sample_x_mm(session.grid),
                         sample_y_mm(session.grid), std::move(replay.sessions[s].predicted)});
  }
  replayed_ = true;
}

double CameraFreeReplay::sum_of_squares(const ModelParams& params) const {
  if (model_params_json(without_measurement_effects(params)) != model_params_json(physical_))
    throw std::invalid_argument("CameraFreeReplay: the parameters simulate other surfaces than the replay's");
  if (!replayed_) return std::numeric_limits<double>::infinity();
  const auto effects = make_effects(params.effects, params.effect_parameters);
  double sum = 0.0;
  for (size_t s = 0; s < sessions_.size(); ++s) {
    const SessionView& view = sessions_[s];
    std::vector<PredictedCapture> seen = view.captures;
    for (PredictedCapture& capture : seen)
      for (const auto& effect : effects) effect->adjust_measurement(view.mesh, view.x_mm, view.y_mm, capture.heights_mm);
    sum += capture_residuals(dataset_.sessions[s], seen).squaredNorm();  // in session order, as dataset_sum_of_squares()
  }
  return sum;
}

}  // namespace hj
