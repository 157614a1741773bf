// The planner interface: a goal surface in, an action sequence and the
// surface it makes out (paper section 5). Planners register by name, so a
// new one is one new file in src/plan/.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/action.h"
#include "model/device_state.h"
#include "model/parameters.h"
#include "sim/simulator.h"

namespace hj {

struct PlanRequest {
  ArrayGeometry geometry;
  SurfaceParameters params;
  // ((R p + 1) x (C p + 1)) goal height of each mesh point (i, j), mm.
  Eigen::MatrixXd goal_mm;
  SimulatorOptions simulator;
};

struct PlanCallbacks {
  // Fraction done in [0, 1] and what is happening.
  std::function<void(double fraction, const std::string& what)> progress;
  // The settled state after an action, for streaming snapshots.
  std::function<void(const DeviceState& state)> snapshot;
  // Polled between actions; true stops the plan with PlanCancelled.
  std::function<bool()> cancelled;
};

struct PlanResult {
  std::vector<Action> steps;  // in the order to apply them, from rest
  DeviceState final_state;    // the predicted surface
};

class PlanCancelled : public std::runtime_error {
 public:
  PlanCancelled() : std::runtime_error("planning was cancelled") {}
};

class Planner {
 public:
  virtual ~Planner() = default;
  virtual std::string name() const = 0;
  // Throws std::invalid_argument on a goal whose shape does not match the
  // mesh or holds non-finite heights; PlanCancelled when cancelled.
  virtual PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const = 0;
};

// Planners by name; each planner file registers itself.
std::unique_ptr<Planner> make_planner(const std::string& name);
std::vector<std::string> planner_names();
void register_planner(const std::string& name, std::function<std::unique_ptr<Planner>()> make);

// The request's simulator options with callbacks.cancelled polled inside
// every settle too, so a cancel stops a long settle, not only the plan
// between actions (catch SettleInterrupted, throw PlanCancelled).
SimulatorOptions simulator_options(const PlanRequest& request, const PlanCallbacks& callbacks);

// The request's simulator settled at rest, its settles cancellable
// (SettleInterrupted becomes PlanCancelled).
Simulator start_simulator(const PlanRequest& request, const PlanCallbacks& callbacks);

// Applies one planned action: cancellation checked first, a cancelled
// settle thrown as PlanCancelled, the action recorded in result.steps and
// the state sent to callbacks.snapshot.
void apply_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks);

// A planner's pressure ceiling: its option (0: none) capped by the device's.
double plan_max_pressure(double option_pa, const SurfaceParameters& params);

// Checks a request's goal against its mesh (shape, finite values).
void validate_plan_request(const PlanRequest& request, const Mesh& mesh);

}  // namespace hj
