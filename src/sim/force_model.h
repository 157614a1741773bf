// The total force on the surface: the sum, in one visible loop, of the
// forces of an ordered list of effects (docs/architecture.md, src/sim).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "sim/effect.h"

namespace hj {

class ForceModel {
 public:
  // Throws std::invalid_argument on invalid parameters.
  ForceModel(const Mesh& mesh, const SurfaceParameters& params, std::vector<std::unique_ptr<Effect>> effects);

  const Mesh& mesh() const { return mesh_; }
  const SurfaceParameters& params() const { return params_; }
  const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_; }

  // f (3 x N) = sum of the effects' forces at x, state otherwise from `state`.
  void forces(const DeviceState& state, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const;
  // f (3 x N) += velocity-dependent (damping) forces.
  void add_damping_forces(const DeviceState& state, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                          Eigen::Matrix3Xd& f) const;
  void add_stiffness(const DeviceState& state, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const;
  // Sum of the conservative effects' energies (J), ignoring the others.
  double conservative_energy(const DeviceState& state, const Eigen::Matrix3Xd& x) const;

  // Points that do not move: the clamped edge (unless an effect frees it,
  // Effect::frees_boundary) and the pinned nodes.
  std::vector<char> fixed_points(const DeviceState& state) const;
  // Sum of the effects' Effect::point_stiffness_bound (N/m).
  double extra_point_stiffness() const;
  // Runs every effect's Effect::after_settle; true if any changed the state.
  bool after_settle(DeviceState& state) const;
  // Applies every effect's Effect::adjust_measurement, in order.
  void adjust_measurement(const Eigen::VectorXd& x_mm, const Eigen::VectorXd& y_mm, Eigen::MatrixXd& heights_mm) const;

 private:
  Mesh mesh_;
  SurfaceParameters params_;
  std::vector<std::unique_ptr<Effect>> effects_;
};

// Largest |F| (N) over points not in `fixed` (3 x N forces).
double max_free_force(const Eigen::Matrix3Xd& f, const std::vector<char>& fixed);

}  // namespace hj
