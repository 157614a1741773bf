#include "sim/implicit_flow.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/process_tuning.h"
#include "sim/shifted_solver.h"
#include "sim/stiffness_matrix.h"

namespace hj {

void ImplicitFlowOptions::validate() const {
  auto bad = [](const char* field, const std::string& why) {
    throw std::invalid_argument(std::string("implicit flow option ") + field + " " + why);
  };
  if (!(force_tolerance_n > 0.0) || !std::isfinite(force_tolerance_n)) bad("force_tolerance_n", "(N) must be > 0");
  if (max_steps < 1) bad("max_steps", "must be at least 1");
  if (newton_iterations < 1) bad("newton_iterations", "must be at least 1");
  if (!(initial_shift > 0.0) || !std::isfinite(initial_shift)) bad("initial_shift", "(x spring_k) must be > 0");
  if (!(max_step_fraction > 0.0) || !std::isfinite(max_step_fraction)) bad("max_step_fraction", "(x h) must be > 0");
}

namespace {

// Newton on a step's implicit equation stops when its residual
// |F(y) - mu (y - x_n)| is this fraction of |F(x_n)|: the path need not be
// followed exactly, and near the end, where mu is small, the steps are
// Newton's with this forcing term.
constexpr double kNewtonForcing = 0.1;
// dt shrinks this much when a step fails, and grows after an easy one.
constexpr double kShiftUp = 4.0, kShiftDownEasy = 0.3, kShiftDown = 0.7;
// ... but not so far that the next step's move, which grows about as dt
// while the shift dominates K, passes this fraction of the cap: a step past
// the cap is thrown away (9 x 12 snap of a pinned jammed plate: 102 of its
// 233 steps were, each after an easy one that had cut mu 3x).
constexpr double kTargetMoveFraction = 0.7;
// Past these (in units of spring_k) the flow has stalled, or is Newton.
// A stall: the 9 x 12 volcano plan at 315-350 Pa creases the net along a
// cell border next to a jammed plate so sharply that the Eq. 3 normals
// there become near-singular (dF/dx ~ 1e13 N/m), and no step, however
// short, solves its implicit equation.
constexpr double kMaxShift = 1e6, kMinShift = 1e-9;

double largest_move(const Eigen::VectorXd& dofs) {
  return dofs.size() == 0 ? 0.0 : dofs.reshaped(3, dofs.size() / 3).colwise().norm().maxCoeff();
}

}  // namespace

SettleReport settle_implicit_flow(const ForceModel& model, DeviceState& state, const ImplicitFlowOptions& options) {
  options.validate();
  tune_process_for_settling();
  const auto start = std::chrono::steady_clock::now();
  const std::vector<char> fixed = model.fixed_points(state);
  StiffnessMatrix k(model.mesh(), fixed, [&](StiffnessSink& sink) { model.add_stiffness(state, state.x, sink); });
  SettleReport report;
  const auto finish = [&] {
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
  };
  if (k.num_dofs() == 0) {
    report.converged = true;
    return finish();
  }
  ShiftedSolver solver;
  const double spring_k = model.params().spring_k;
  const double max_step = options.max_step_fraction * model.mesh().spacing();
  double mu = options.initial_shift * spring_k;

  Eigen::Matrix3Xd f;
  model.forces(state, state.x, f);
  Eigen::VectorXd residual = k.gather(f);  // F(x_n) over the free DOFs
  Eigen::VectorXd y, g, d, moved;
  Eigen::Matrix3Xd f_y;
  for (int step = 0; step < options.max_steps; ++step) {
    if (options.interrupted && options.interrupted()) throw SettleInterrupted();
    report.residual_n = max_free_force(f, fixed);
    if (report.residual_n < options.force_tolerance_n) {
      report.converged = true;
      return finish();
    }
    if (mu > kMaxShift * spring_k) break;  // dt cut to nothing: stalled
    ++report.iterations;
    // One backward Euler step from x_n: Newton on g(y) = F(y) - mu (y - x_n).
    const double target = kNewtonForcing * residual.norm();
    moved.setZero(residual.size());  // y - x_n
    g = residual;
    bool solved = false;
    int newton = 0;
    for (; newton < options.newton_iterations; ++newton) {
      const Eigen::Matrix3Xd y_points = state.x + k.scatter(moved);
      k.set_zero();
      model.add_stiffness(state, y_points, k);
      for (int p : k.free_points()) k.add(p, p, mu * Eigen::Matrix3d::Identity());
      if (!solver.solve(k.matrix(), mu, g, d) || !d.allFinite()) break;
      moved += d;
      // A move past the cap: dt is too long for the path to be followed.
      if (largest_move(moved) > max_step) break;
      model.forces(state, state.x + k.scatter(moved), f_y);
      g = k.gather(f_y) - mu * moved;
      if (!g.allFinite()) break;
      if (g.norm() <= target) {
        solved = true;
        break;
      }
    }
    if (!solved) {
      mu *= kShiftUp;
      continue;
    }
    state.x += k.scatter(moved);
    f.swap(f_y);
    residual = k.gather(f);
    if (options.abandon && options.abandon(state.x, max_free_force(f, fixed))) break;
    const double easier = mu * (newton <= 1 ? kShiftDownEasy : newton <= 3 ? kShiftDown : 1.0);
    const double within_cap = mu * largest_move(moved) / (kTargetMoveFraction * max_step);
    mu = std::max({easier, within_cap, kMinShift * spring_k});
  }
  report.residual_n = max_free_force(f, fixed);
  return finish();
}

}  // namespace hj
