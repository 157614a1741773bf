#include "plan/algorithm2_levelled.h"

#include "plan/algorithm2_refined.h"

namespace hj {

std::unique_ptr<Planner> make_algorithm2_levelled(double height_scale) {
  Algorithm2RefinedOptions options;
  options.height_scales = {height_scale};
  options.jam_below_levelling = {false};
  options.bisect_pins = {false};
  options.name = "algorithm2-levelled";
  return std::make_unique<Algorithm2Refined>(options);
}

namespace {
const bool registered = (register_planner("algorithm2-levelled", [] { return make_algorithm2_levelled(); }), true);
}  // namespace

}  // namespace hj
