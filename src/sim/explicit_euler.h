// The paper's dynamic relaxation, kept as the reference: explicit
// (semi-implicit, velocity first) Euler steps of m a = F(x) + F_damp(x, v)
// from rest at the previous state, until the paper's equilibrium test holds:
// the sums of the free points' speeds and accelerations both below their
// tolerances.
#pragma once

#include <functional>

#include "model/device_state.h"
#include "sim/force_model.h"
#include "sim/settle_report.h"

namespace hj {

struct ExplicitEulerOptions {
  // Time step, s; 0 picks 0.3 of the stability limit of the stiffest
  // spring or jammed bending spring.
  double time_step_s = 0.0;
  // Drag on every point, as a rate c/m in 1/s: damps the out-of-plane
  // modes that dampers along near-flat springs cannot reach. Changes the
  // path, not the equilibrium.
  double drag_rate_per_s = 30.0;
  // The equilibrium test, as means over free points (the sums divided by
  // their count, so one tolerance serves every mesh size).
  double mean_speed_tolerance_m_per_s = 1e-8;
  double mean_accel_tolerance_m_per_s2 = 1e-6;
  long max_steps = 50'000'000;
  // Polled every 1,024 steps; true throws SettleInterrupted.
  std::function<bool()> interrupted;

  void validate() const;
};

// Time step picked when options.time_step_s is 0.
double explicit_time_step(const ForceModel& model, const ExplicitEulerOptions& options);

SettleReport settle_explicit(const ForceModel& model, DeviceState& state, const ExplicitEulerOptions& options = {});

}  // namespace hj
