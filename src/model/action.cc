#include "model/action.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace hj {

const char* Action::op_name() const {
  switch (op) {
    case Op::kSetPressure: return "set_pressure";
    case Op::kJam: return "jam";
    case Op::kUnjam: return "unjam";
    case Op::kPin: return "pin";
    case Op::kUnpin: return "unpin";
  }
  return "?";
}

std::string Action::describe() const {
  std::ostringstream out;
  out << op_name() << ' ';
  if (op == Op::kSetPressure)
    out << pressure_pa / 1000.0 << " kPa";
  else
    out << '[' << a << ", " << b << ']';
  return out.str();
}

void Action::validate(const Mesh& mesh, const SurfaceParameters& params) const {
  std::ostringstream err;
  switch (op) {
    case Op::kSetPressure:
      if (!std::isfinite(pressure_pa) || pressure_pa < 0.0 || pressure_pa > params.max_pressure_pa) {
        err << "unsafe pressure " << pressure_pa / 1000.0 << " kPa: must be within [0, "
            << params.max_pressure_pa / 1000.0 << "] kPa";
        throw std::invalid_argument(err.str());
      }
      return;
    case Op::kJam:
    case Op::kUnjam:
      if (!mesh.valid_cell(a, b)) {
        err << "cell [" << a << ", " << b << "] is out of range: rows 0.." << mesh.rows() - 1 << ", cols 0.."
            << mesh.cols() - 1;
        throw std::invalid_argument(err.str());
      }
      return;
    case Op::kPin:
    case Op::kUnpin:
      if (!mesh.valid_node(a, b)) {
        err << "node [" << a << ", " << b << "] is out of range: ";
        if (mesh.num_nodes() == 0)
          err << "a " << mesh.rows() << " x " << mesh.cols() << " array has no pinnable nodes";
        else
          err << "a in 1.." << mesh.rows() - 1 << ", b in 1.." << mesh.cols() - 1;
        throw std::invalid_argument(err.str());
      }
      return;
  }
}

}  // namespace hj
