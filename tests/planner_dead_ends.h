// Two planners' states where the flow passes folded meshes
// (sim/dead_end_watch.h), from real plans (hapticjam plan GOAL --planner
// algorithm2): one a dead end, one a snap-through that settles.
#pragma once

#include <utility>
#include <vector>

#include "model/action.h"

namespace hj::testing {

inline void add_jams(std::vector<Action>& steps, std::initializer_list<std::pair<int, int>> cells) {
  for (const auto& [r, c] : cells) steps.push_back(Action::jam(r, c));
}

// stanford_bunny.stl on 9 x 12, its first 29 steps: 25 cells jammed in the
// sag, 200 Pa. At 250 Pa the flow folds the sag past 120 degrees and wanders
// in place: a dead end.
inline std::vector<Action> bunny_9x12_jammed_sag() {
  std::vector<Action> steps{Action::set_pressure(50.0)};
  add_jams(steps, {{0, 0}, {0, 2}, {0, 3}, {0, 4}, {0, 9}, {1, 10}, {4, 0}, {4, 5}, {4, 11}, {5, 6},
                   {5, 10}, {6, 2}, {6, 3}, {6, 4}, {6, 5}, {6, 9}, {7, 5}, {7, 6}, {7, 7}, {8, 1}});
  for (double p : {100.0, 150.0, 200.0}) steps.push_back(Action::set_pressure(p));
  add_jams(steps, {{2, 3}, {5, 11}, {8, 5}, {8, 6}, {8, 7}});
  return steps;
}

// volcano_maunga_whau.csv on 5 x 7, its first 27 steps: 20 cells jammed on
// the way to 300 Pa. At 350 Pa the sag inverts into a dome through states
// folded past 120 degrees for some 30 flow steps, moving all the while.
inline std::vector<Action> volcano_5x7_jammed_sag() {
  std::vector<Action> steps{Action::set_pressure(50.0)};
  add_jams(steps, {{0, 1}, {0, 4}, {0, 5}, {1, 3}, {2, 0}, {2, 2}, {4, 2}, {4, 4}, {4, 5}});
  steps.push_back(Action::set_pressure(100.0));
  add_jams(steps, {{2, 6}});
  steps.push_back(Action::set_pressure(150.0));
  add_jams(steps, {{2, 1}, {3, 6}});
  steps.push_back(Action::set_pressure(200.0));
  add_jams(steps, {{2, 5}, {4, 1}});
  steps.push_back(Action::set_pressure(250.0));
  add_jams(steps, {{3, 3}});
  steps.push_back(Action::set_pressure(300.0));
  add_jams(steps, {{0, 6}, {1, 0}, {3, 1}, {3, 4}, {4, 3}, {4, 6}});
  return steps;
}

// luxembourg_elev.csv on 9 x 12, its first 49 steps: 44 cells jammed in the
// sag, 200 Pa. At 250 Pa the flow swings in a cycle of about 40 steps, its
// folds coming and going around 120 degrees, back within 0.4 mm of itself.
inline std::vector<Action> luxembourg_9x12_cycling_sag() {
  std::vector<Action> steps{Action::set_pressure(50.0)};
  add_jams(steps, {{0, 3}, {0, 4}, {0, 5}, {0, 6}, {0, 7}, {0, 8}, {0, 9}, {1, 1}, {1, 2}, {1, 6}, {1, 8},
                   {1, 9}, {2, 1}, {2, 10}, {2, 11}, {3, 0}, {3, 1}, {3, 5}, {4, 5}, {4, 8}, {4, 10}, {4, 11},
                   {5, 0}, {5, 1}, {5, 2}, {5, 6}, {5, 10}, {5, 11}, {6, 3}, {6, 6}, {6, 8}, {6, 10}, {6, 11},
                   {7, 0}, {7, 4}, {7, 5}, {7, 7}, {7, 8}, {7, 9}, {8, 3}, {8, 6}});
  for (double p : {100.0, 150.0}) steps.push_back(Action::set_pressure(p));
  add_jams(steps, {{0, 11}, {5, 8}, {8, 10}});
  steps.push_back(Action::set_pressure(200.0));
  add_jams(steps, {{8, 7}});
  return steps;
}

}  // namespace hj::testing
