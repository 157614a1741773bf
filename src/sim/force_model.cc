#include "sim/force_model.h"

namespace hj {

ForceModel::ForceModel(const Mesh& mesh, const SurfaceParameters& params,
                       std::vector<std::unique_ptr<Effect>> effects)
    : mesh_(mesh), params_(params), effects_(std::move(effects)) {
  params_.validate();
}

void ForceModel::forces(const DeviceState& state, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const {
  f.setZero(3, mesh_.num_points());
  const ForceContext ctx{mesh_, params_, state};
  for (const auto& effect : effects_) effect->add_forces(ctx, x, f);
}

void ForceModel::add_damping_forces(const DeviceState& state, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                                    Eigen::Matrix3Xd& f) const {
  const ForceContext ctx{mesh_, params_, state};
  for (const auto& effect : effects_) effect->add_damping_forces(ctx, x, v, f);
}

void ForceModel::add_stiffness(const DeviceState& state, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const {
  const ForceContext ctx{mesh_, params_, state};
  for (const auto& effect : effects_) effect->add_stiffness(ctx, x, sink);
}

double ForceModel::conservative_energy(const DeviceState& state, const Eigen::Matrix3Xd& x) const {
  const ForceContext ctx{mesh_, params_, state};
  double e = 0.0;
  for (const auto& effect : effects_)
    if (auto ei = effect->energy(ctx, x)) e += *ei;
  return e;
}

double max_free_force(const Eigen::Matrix3Xd& f, const std::vector<char>& fixed) {
  double m = 0.0;
  for (int p = 0; p < f.cols(); ++p)
    if (!fixed[p]) m = std::max(m, f.col(p).norm());
  return m;
}

}  // namespace hj
