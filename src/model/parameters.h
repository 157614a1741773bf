// Physical parameters of the baseline surface model (docs/model.md,
// "Parameters fitted on the paper's device"). Fixed for a run; the mutable
// device state lives in DeviceState.
#pragma once

#include "model/mesh.h"

namespace hj {

struct SurfaceParameters {
  double mass_kg = 0.55;             // M, whole membrane incl. fixed points
  double spring_k = 64.5;            // k, N/m
  double damping_b = 0.5;            // b, N s/m, along each spring (dynamics only)
  double kappa_jam = 4.79;           // N m/rad, jammed bending stiffness
  double gravity = 9.81;             // g, m/s^2
  double max_pressure_pa = 3450.0;   // P_max, gauge

  // Throws std::invalid_argument naming the field (and its unit) that is
  // NaN, infinite, negative or zero where it must be positive.
  void validate() const;

  // The paper's fitted values, with the mass scaled by cell count so that a
  // larger array made of the same membrane keeps the paper's areal density
  // (and so its levelling pressure of 0.301 kPa).
  static SurfaceParameters paper_defaults(const ArrayGeometry& geometry);

  // P = M g / (R s C s): a flat surface is in equilibrium at exactly this.
  double levelling_pressure_pa(const Mesh& mesh) const { return mass_kg * gravity / mesh.area(); }
  double point_mass(const Mesh& mesh) const { return mass_kg / mesh.num_points(); }
};

}  // namespace hj
