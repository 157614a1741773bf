// The membrane's mass from the levelling pressure, as the paper measures it:
// the pressure at which the centre of an unjammed, unpinned array crosses
// the level of its clamped edge, then M = P A / g (docs/model.md, "Forces":
// a flat surface is in equilibrium at exactly P = M g / A).
#pragma once

#include <string>

#include "calib/dataset.h"

namespace hj {

struct LevellingEstimate {
  bool found = false;
  double pressure_pa = 0.0;  // interpolated zero crossing
  double mass_kg = 0.0;      // P A / g
  std::string session;       // where the crossing was seen
  double below_pa = 0.0;     // the two captures' pressures around it
  double above_pa = 0.0;
};

// The measured height at the array's centre: the mean of the samples seen
// within a quarter cell of it (NaN if none).
double centre_height_mm(const Session& session, const MeasuredCapture& capture);

// The first sign change of the centre height between two consecutive
// unjammed, unpinned captures of a session at rising pressure, located by
// fitting the law of a net without pre-tension, whose centre deflects as the
// cube root of its net load, h = a cbrt(P - P0), to that session's unjammed,
// unpinned captures. found = false if no session has a crossing.
LevellingEstimate levelling_mass(const Dataset& dataset, double gravity);

}  // namespace hj
