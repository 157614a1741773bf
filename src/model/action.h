// The five device actions (docs/model.md, "States and actions"), in the step
// vocabulary of docs/session-format.md.
#pragma once

#include <string>

#include "model/mesh.h"
#include "model/parameters.h"

namespace hj {

struct Action {
  enum class Op { kSetPressure, kJam, kUnjam, kPin, kUnpin };
  Op op = Op::kSetPressure;
  double pressure_pa = 0.0;  // kSetPressure
  int a = 0;                 // cell row or node a
  int b = 0;                 // cell col or node b

  static Action set_pressure(double pa) { return {Op::kSetPressure, pa, 0, 0}; }
  static Action jam(int r, int c) { return {Op::kJam, 0.0, r, c}; }
  static Action unjam(int r, int c) { return {Op::kUnjam, 0.0, r, c}; }
  static Action pin(int a, int b) { return {Op::kPin, 0.0, a, b}; }
  static Action unpin(int a, int b) { return {Op::kUnpin, 0.0, a, b}; }

  // Throws std::invalid_argument naming what is wrong: a pressure that is
  // NaN or outside [0, P_max], a cell or node out of range.
  void validate(const Mesh& mesh, const SurfaceParameters& params) const;
  // "set_pressure 0.301 kPa", "jam [0, 3]", ...
  std::string describe() const;
  // Session-format op name: set_pressure, jam, unjam, pin, unpin.
  const char* op_name() const;
};

}  // namespace hj
