#include "sim/force_model.h"

#include <algorithm>

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

std::vector<char> ForceModel::fixed_points(const DeviceState& state) const {
  std::vector<char> fixed = state.fixed_points(mesh_);
  const bool edge_free =
      std::any_of(effects_.begin(), effects_.end(), [](const auto& e) { return e->frees_boundary(); });
  if (!edge_free) return fixed;
  for (int p = 0; p < mesh_.num_points(); ++p)
    if (mesh_.is_boundary(p)) fixed[p] = 0;
  return fixed;
}

double ForceModel::extra_point_stiffness() const {
  double k = 0.0;
  for (const auto& effect : effects_) k += effect->point_stiffness_bound(mesh_, params_);
  return k;
}

bool ForceModel::after_settle(DeviceState& state) const {
  bool changed = false;
  for (const auto& effect : effects_) changed |= effect->after_settle(mesh_, params_, state);
  return changed;
}

void ForceModel::adjust_measurement(const Eigen::VectorXd& x_mm, const Eigen::VectorXd& y_mm,
                                    Eigen::MatrixXd& heights_mm) const {
  for (const auto& effect : effects_) effect->adjust_measurement(mesh_, x_mm, y_mm, heights_mm);
}

double max_free_force(const Eigen::Matrix3Xd& f, const std::vector<char>& fixed) {
  double m = 0.0;
  for (int p = 0; p < f.cols(); ++p)
    if (!fixed[p]) m = std::max(m, f.col(p).norm());
  return m;
}

}  // namespace hj
