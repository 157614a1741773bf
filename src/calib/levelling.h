// The membrane's mass from the levelling pressure, as the paper measures it:
// the pressure at which the centre of an unjammed, unpinned array crosses
// the level of its clamped edge, then M = P A / g (docs/model.md, "Forces":
// a flat surface is in equilibrium at exactly P = M g / A).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "calib/dataset.h"

namespace hj {

struct LevellingEstimate {
  bool found = false;
  double pressure_pa = 0.0;  // interpolated zero crossing
  double mass_kg = 0.0;      // P A / g
  std::string session;       // where the crossing was seen
  double below_pa = 0.0;     // the two captures' pressures around it
  double above_pa = 0.0;
  // The 95 % interval of the crossing and so of the levelling mass, from
  // the crossing's own evidence: fit_cube_root_crossing on the two captures
  // either side of it (where the cube-root law holds), widened to hold the
  // estimate; points and scatter_mm are that local fit's.
  double pressure_low_pa = 0.0, pressure_high_pa = 0.0;
  double mass_low_kg = 0.0, mass_high_kg = 0.0;
  int points = 0;            // unjammed, unpinned captures in the cube-root fit
  double scatter_mm = 0.0;   // their rms scatter about it
};

struct CubeRootCrossing {
  double pressure_pa = 0.0;  // P0
  double low_pa = 0.0;       // its 95 % interval
  double high_pa = 0.0;
  double scatter_mm = 0.0;   // rms of h - a cbrt(P - P0), on n - 2 degrees of freedom
};

// Fits h = a cbrt(P - P0) to (pressure Pa, centre height mm) points, P0 in
// [lo, hi] (the two captures around the sign change). The 95 % interval of
// P0 is its profile: the P0 (with a refitted) whose squared misfit exceeds
// the minimum by at most t^2 s^2, s^2 = minimum / (n - 2), t the 97.5 %
// point of Student's t on n - 2 degrees of freedom. So it is set by the
// scatter of the heights about the law and by how steeply the height
// changes with pressure where the captures are (the pressure steps), and it
// may reach beyond [lo, hi]. With two points or fewer it is [lo, hi].
CubeRootCrossing fit_cube_root_crossing(const std::vector<std::pair<double, double>>& points, double lo, double hi);

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
