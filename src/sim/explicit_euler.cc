#include "sim/explicit_euler.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/process_tuning.h"

namespace hj {

void ExplicitEulerOptions::validate() const {
  auto bad = [](const char* field, const char* why) {
    throw std::invalid_argument(std::string("explicit Euler option ") + field + " " + why);
  };
  if (!(time_step_s >= 0.0) || !std::isfinite(time_step_s)) bad("time_step_s", "(s) must be >= 0 (0 = automatic)");
  if (!(drag_rate_per_s >= 0.0) || !std::isfinite(drag_rate_per_s)) bad("drag_rate_per_s", "(1/s) must be >= 0");
  if (!(mean_speed_tolerance_m_per_s > 0.0)) bad("mean_speed_tolerance_m_per_s", "(m/s) must be > 0");
  if (!(mean_accel_tolerance_m_per_s2 > 0.0)) bad("mean_accel_tolerance_m_per_s2", "(m/s^2) must be > 0");
  if (max_steps < 1) bad("max_steps", "must be at least 1");
}

double explicit_time_step(const ForceModel& model, const ExplicitEulerOptions& options) {
  if (options.time_step_s > 0.0) return options.time_step_s;
  const SurfaceParameters& p = model.params();
  const double m = p.point_mass(model.mesh()), h = model.mesh().spacing();
  // Largest lattice stiffness per point: 8 k from springs; a jammed bending
  // spring adds about 16 kappa / h^2 per direction; effects add their bounds.
  const double stiffness = 8.0 * p.spring_k + 32.0 * p.kappa_jam / (h * h) + model.extra_point_stiffness();
  const double omega_max = std::sqrt(stiffness / m);
  const double damping_rate = 8.0 * p.damping_b / m + options.drag_rate_per_s;
  return 0.3 * std::min(2.0 / omega_max, 2.0 / damping_rate);
}

SettleReport settle_explicit(const ForceModel& model, DeviceState& state, const ExplicitEulerOptions& options) {
  options.validate();
  tune_process_for_settling();
  const auto start = std::chrono::steady_clock::now();
  const Mesh& mesh = model.mesh();
  const std::vector<char> fixed = model.fixed_points(state);
  int free_count = 0;
  for (char c : fixed) free_count += !c;
  const double m = model.params().point_mass(mesh);
  const double drag = options.drag_rate_per_s * m;
  const double dt = explicit_time_step(model, options);

  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, mesh.num_points()), f;
  SettleReport report;
  for (long step = 0; step < options.max_steps; ++step) {
    if ((step & 1023) == 0 && options.interrupted && options.interrupted()) throw SettleInterrupted();
    model.forces(state, state.x, f);
    model.add_damping_forces(state, state.x, v, f);
    f -= drag * v;
    double speed_sum = 0.0, accel_sum = 0.0;
    for (int p = 0; p < mesh.num_points(); ++p) {
      if (fixed[p]) continue;
      const Eigen::Vector3d a = f.col(p) / m;
      v.col(p) += dt * a;
      state.x.col(p) += dt * v.col(p);
      speed_sum += v.col(p).norm();
      accel_sum += a.norm();
    }
    report.iterations = static_cast<int>(std::min<long>(step + 1, INT32_MAX));
    if (!std::isfinite(speed_sum)) break;
    if (speed_sum < options.mean_speed_tolerance_m_per_s * free_count &&
        accel_sum < options.mean_accel_tolerance_m_per_s2 * free_count) {
      report.converged = true;
      break;
    }
  }
  model.forces(state, state.x, f);
  report.residual_n = max_free_force(f, fixed);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace hj
