#include "device/status_mirror.h"

#include <algorithm>

namespace hj::device {

void mirror_action(DeviceStatus& s, const Action& action) {
  switch (action.op) {
    case Action::Op::kSetPressure: s.pressure_pa = action.pressure_pa; break;
    case Action::Op::kJam:
    case Action::Op::kUnjam: {
      const long i = static_cast<long>(action.a) * s.cols + action.b;
      if (i >= 0 && i < static_cast<long>(s.cell_jammed.size())) s.cell_jammed[i] = action.op == Action::Op::kJam;
      break;
    }
    case Action::Op::kPin:
    case Action::Op::kUnpin: {
      const long i = static_cast<long>(action.a) * (s.cols + 1) + action.b;
      if (i >= 0 && i < static_cast<long>(s.node_pinned.size())) s.node_pinned[i] = action.op == Action::Op::kPin;
      break;
    }
  }
}

void mirror_vent(DeviceStatus& s) {
  s.pressure_pa = 0.0;
  std::fill(s.cell_jammed.begin(), s.cell_jammed.end(), 0);
  std::fill(s.node_pinned.begin(), s.node_pinned.end(), 0);
}

}  // namespace hj::device
