// What a settle to static equilibrium did, for progress lines and benchmarks.
#pragma once

#include <stdexcept>

namespace hj {

// A settle stopped because its caller asked (SimulatorOptions::interrupted),
// e.g. a client that cancelled or whose deadline passed.
class SettleInterrupted : public std::runtime_error {
 public:
  SettleInterrupted() : std::runtime_error("the settle was interrupted") {}
};

// An action after which the simulator found no static equilibrium (or, with
// SimulatorOptions::refuse_folded, only a folded one); the state is left as
// it was before the action.
class NoEquilibrium : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SettleReport {
  bool converged = false;
  int iterations = 0;        // Newton steps or time steps
  int restarts = 0;          // moves off a saddle or singular state
  // Ended on an equilibrium with a weakly unstable mode that a push did not
  // leave within StaticSolverOptions::push_iterations.
  bool marginal = false;
  double residual_n = 0.0;   // largest |F| on a free point at the end, N
  double seconds = 0.0;      // wall time
};

}  // namespace hj
