// The embedded default job: the paper's Fig. 7 sequence on its 3 x 4 device,
// levelled from above, as a session file (docs/session-format.md).
#pragma once

namespace hj::cli {

inline constexpr const char* kDemoSessionJson = R"({
  "format": "hapticjam.session/1",
  "name": "paper-fig7-demo",
  "device": {"rows": 3, "cols": 4, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
  "sensor": {"kind": "depth camera", "resolution_mm": 1.0, "accuracy_mm": 3.0},
  "grid": {"nx": 77, "ny": 58, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 2.0, "dy_mm": 2.0},
  "steps": [
    {"op": "capture", "frame": "frames/000.csv", "label": "rest"},
    {"op": "set_pressure", "kpa": 0.60},
    {"op": "set_pressure", "kpa": 0.301},
    {"op": "jam", "cell": [0, 2]}, {"op": "jam", "cell": [0, 3]},
    {"op": "jam", "cell": [2, 2]}, {"op": "jam", "cell": [2, 3]},
    {"op": "pin", "node": [1, 2]}, {"op": "pin", "node": [2, 2]},
    {"op": "pin", "node": [1, 3]}, {"op": "pin", "node": [2, 3]},
    {"op": "capture", "frame": "frames/001.csv", "label": "sequence 1"},
    {"op": "set_pressure", "kpa": 0.414},
    {"op": "jam", "cell": [0, 0]}, {"op": "pin", "node": [1, 1]},
    {"op": "capture", "frame": "frames/002.csv", "label": "sequence 2"},
    {"op": "set_pressure", "kpa": 1.73},
    {"op": "capture", "frame": "frames/003.csv", "label": "sequence 3"}
  ]
}
)";

}  // namespace hj::cli
