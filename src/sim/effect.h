// One physical effect of the surface model as a force term (docs/model.md,
// "Forces"). The simulator sums the terms of its effect list in one loop, so
// each can be switched off, inspected and tested alone.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string_view>
#include <vector>

#include "model/device_state.h"
#include "model/mesh.h"
#include "model/parameters.h"

namespace hj {

// What an effect reads besides the positions: the fixed mesh and parameters
// and the device state (pressure, jammed cells and their phi_eq, pins).
struct ForceContext {
  const Mesh& mesh;
  const SurfaceParameters& params;
  const DeviceState& state;
};

// Receives stiffness blocks K(row, col) += block, with K = -dF/dx the
// negative force Jacobian (3 x 3 per point pair). Pairs must lie within the
// stencil |di| + |dj| <= 2 of each other.
class StiffnessSink {
 public:
  virtual ~StiffnessSink() = default;
  virtual void add(int row_point, int col_point, const Eigen::Matrix3d& block) = 0;
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string_view name() const = 0;
  // f (3 x N) += this effect's force at positions x (3 x N). Forces on fixed
  // points may be written; they are ignored.
  virtual void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const = 0;
  // -dF/dx of add_forces, exactly (the static solver's Newton steps use it).
  virtual void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& k) const = 0;
  // Velocity-dependent forces (dampers), used only by dynamic integrators.
  virtual void add_damping_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                                  Eigen::Matrix3Xd& f) const {}
  // Potential energy (J) where the effect is conservative, so that tests can
  // check force = -grad E; nullopt for follower loads such as pressure.
  virtual std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const {
    return std::nullopt;
  }

  // --- Optional hooks of the non-baseline effects (all no-ops by default) ---

  // Largest stiffness (N/m) this effect adds at one point, for the explicit
  // integrator's stable time step.
  virtual double point_stiffness_bound(const Mesh& mesh, const SurfaceParameters& params) const { return 0.0; }
  // True if the clamped edge is free to move under this effect's forces
  // (it then supplies what holds the edge); pinned nodes stay fixed.
  virtual bool frees_boundary() const { return false; }
  // Called by Simulator after each settle to equilibrium: may change the
  // state (e.g. a jam's rest angles creeping toward the current ones) and
  // returns true if it did, so that the simulator settles once more.
  virtual bool after_settle(const Mesh& mesh, const SurfaceParameters& params, DeviceState& state) const {
    return false;
  }
  // Measurement effects: changes the heights (ny x nx, mm, NaN = unseen) a
  // camera would report for a predicted surface sampled at x_mm (nx) by
  // y_mm (ny) in the device frame. Physical effects leave them alone.
  virtual void adjust_measurement(const Mesh& mesh, const Eigen::VectorXd& x_mm, const Eigen::VectorXd& y_mm,
                                  Eigen::MatrixXd& heights_mm) const {}
};

}  // namespace hj
