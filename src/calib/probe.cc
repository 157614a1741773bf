#include "calib/probe.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "sim/settle_report.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"

namespace hj {

namespace {

// Enough pressures to tell a stiffening (the dome's height against pressure
// bends) from a softer spring, few enough to be cheap.
constexpr int kProbeLevels = 4;
constexpr double kProbeHeightMargin = 1.5;

// The first of 9 pressures from `from_pa` to `to_pa` at which the free
// membrane of `model` domes to `height_mm` (to_pa if none does, or if a
// settle fails).
double pressure_reaching(const ArrayGeometry& geometry, const ModelParams& model, const ReplayOptions& replay,
                         double from_pa, double to_pa, double height_mm) {
  constexpr int kSteps = 8;
  Simulator simulator(geometry, model.surface, simulator_options(model, replay));
  try {
    for (int k = 0; k <= kSteps; ++k) {
      const double pressure = from_pa + (to_pa - from_pa) * k / kSteps;
      simulator.apply(Action::set_pressure(pressure));
      if (point_heights(simulator.mesh(), simulator.state().x).maxCoeff() * 1000.0 >= height_mm) return pressure;
    }
  } catch (const NoEquilibrium&) {
  }
  return to_pa;
}

}  // namespace

std::vector<Action> probe_actions(double from_pa, double to_pa, int levels) {
  if (!(from_pa > 0.0 && from_pa <= to_pa) || levels < 1)
    throw std::invalid_argument("probe: pressures from " + std::to_string(from_pa) + " to " + std::to_string(to_pa) +
                                " Pa in " + std::to_string(levels) + " levels; need 0 < from <= to and levels >= 1");
  std::vector<Action> out;
  for (int k = 0; k < levels; ++k)
    out.push_back(Action::set_pressure(levels == 1 ? to_pa : from_pa + (to_pa - from_pa) * k / (levels - 1)));
  return out;
}

double shaping_pressure_pa(const std::vector<Action>& plan) {
  double pressure = 0.0, top = 0.0, shaping = 0.0;
  for (const Action& a : plan) {
    if (a.op == Action::Op::kSetPressure)
      pressure = a.pressure_pa, top = std::max(top, pressure);
    else if (a.op == Action::Op::kJam || a.op == Action::Op::kPin)
      shaping = std::max(shaping, pressure);
  }
  return shaping > 0.0 ? shaping : top;
}

std::vector<Action> probe_for_plan(const ArrayGeometry& geometry, const ModelParams& model, const ReplayOptions& replay,
                                   double from_pa, const std::vector<Action>& plan, double goal_top_mm) {
  const double limit = model.surface.max_pressure_pa;
  const double shaping = std::min(limit, std::max(shaping_pressure_pa(plan), 2.0 * from_pa));
  const double reach =
      pressure_reaching(geometry, model, replay, from_pa, shaping, kProbeHeightMargin * goal_top_mm);
  const double top = std::min(shaping, std::max(reach, 2.0 * from_pa));
  return probe_actions(std::min(from_pa, top), top, kProbeLevels);
}

}  // namespace hj
