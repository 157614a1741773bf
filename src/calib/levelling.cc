#include "calib/levelling.h"

#include <boost/math/distributions/students_t.hpp>
#include <algorithm>
#include <cmath>

namespace hj {

double centre_height_mm(const Session& session, const MeasuredCapture& capture) {
  const double s = session.device.cell_size_mm;
  const double cx = session.device.cols * s / 2.0, cy = session.device.rows * s / 2.0;
  double sum = 0.0;
  int n = 0;
  for (int iy = 0; iy < session.grid.ny; ++iy)
    for (int ix = 0; ix < session.grid.nx; ++ix) {
      const double h = capture.heights_mm(iy, ix);
      if (std::isnan(h) || std::hypot(session.grid.x_mm(ix) - cx, session.grid.y_mm(iy) - cy) > s / 4.0) continue;
      sum += h;
      ++n;
    }
  return n ? sum / n : std::nan("");
}

namespace {

// Squared misfit of h = a cbrt(P - p0) over the points, a in closed form.
double cube_root_misfit(const std::vector<std::pair<double, double>>& points, double p0) {
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (auto [p, h] : points) {
    const double x = std::cbrt(p - p0);
    sxy += x * h;
    sxx += x * x;
    syy += h * h;
  }
  return sxx > 0.0 ? syy - sxy * sxy / sxx : syy;
}

// Walks from `from` in steps of `step` while the misfit stays within
// `threshold`, at most `limit` steps; the last p0 inside.
double profile_end(const std::vector<std::pair<double, double>>& points, double from, double step, double threshold,
                   int limit) {
  double inside = from;
  for (int k = 1; k <= limit; ++k) {
    const double p0 = from + k * step;
    if (cube_root_misfit(points, p0) > threshold) break;
    inside = p0;
  }
  return inside;
}

}  // namespace

CubeRootCrossing fit_cube_root_crossing(const std::vector<std::pair<double, double>>& points, double lo, double hi) {
  CubeRootCrossing out;
  double best = 0.5 * (lo + hi), best_misfit = cube_root_misfit(points, best);
  constexpr int kSteps = 2000;
  const double step = (hi - lo) / kSteps;
  for (int k = 0; k <= kSteps; ++k) {
    const double p0 = lo + step * k;
    const double m = cube_root_misfit(points, p0);
    if (m < best_misfit) best_misfit = m, best = p0;
  }
  out.pressure_pa = best;
  const int dof = static_cast<int>(points.size()) - 2;
  if (dof < 1 || !(step > 0.0)) {
    out.low_pa = lo;
    out.high_pa = hi;
    return out;
  }
  const double s2 = best_misfit / dof;
  out.scatter_mm = std::sqrt(s2);
  const double t = boost::math::quantile(boost::math::complement(boost::math::students_t(dof), 0.025));
  const double threshold = best_misfit + t * t * s2;
  // The interval may reach beyond the captures around the crossing; it is
  // searched out to 20 of their spacings on either side.
  out.low_pa = profile_end(points, best, -step, threshold, 20 * kSteps);
  out.high_pa = profile_end(points, best, step, threshold, 20 * kSteps);
  return out;
}

namespace {

// (pressure, centre height) of the session's unjammed, unpinned captures.
std::vector<std::pair<double, double>> centre_heights(const MeasuredSession& measured) {
  std::vector<std::pair<double, double>> points;
  for (const auto& c : measured.captures) {
    if (c.jammed_count() > 0 || !c.pinned.empty()) continue;
    const double h = centre_height_mm(measured.session, c);
    if (!std::isnan(h)) points.push_back({c.pressure_pa, h});
  }
  return points;
}

// The two points at or below `below` and the two at or above `above`
// nearest to them (fewer if the session has fewer).
std::vector<std::pair<double, double>> around(std::vector<std::pair<double, double>> points, double below,
                                              double above) {
  std::sort(points.begin(), points.end());
  std::vector<std::pair<double, double>> out;
  int under = 0;
  for (auto it = points.rbegin(); it != points.rend() && under < 2; ++it)
    if (it->first <= below) out.push_back(*it), ++under;
  int over = 0;
  for (auto it = points.begin(); it != points.end() && over < 2; ++it)
    if (it->first >= above) out.push_back(*it), ++over;
  return out;
}

}  // namespace

LevellingEstimate levelling_mass(const Dataset& dataset, double gravity) {
  LevellingEstimate out;
  for (const MeasuredSession& measured : dataset.sessions) {
    const Session& session = measured.session;
    const MeasuredCapture* previous = nullptr;
    double previous_h = 0.0;
    for (const MeasuredCapture& capture : measured.captures) {
      if (capture.jammed_count() > 0 || !capture.pinned.empty()) {
        previous = nullptr;
        continue;
      }
      const double h = centre_height_mm(session, capture);
      if (std::isnan(h)) continue;
      if (previous && capture.pressure_pa > previous->pressure_pa && previous_h < 0.0 && h >= 0.0) {
        out.found = true;
        const std::vector<std::pair<double, double>> points = centre_heights(measured);
        CubeRootCrossing crossing = fit_cube_root_crossing(points, previous->pressure_pa, capture.pressure_pa);
        // The interval from the captures around the crossing only, where the
        // cube-root law holds; far from it the law's systematic misfit is
        // not scatter (on demo-baseline the fit over the whole sweep puts
        // the crossing 23 Pa high, with an interval 301..335 Pa that misses
        // the true 294 Pa). Widened to hold the estimate from all captures.
        const std::vector<std::pair<double, double>> near = around(points, previous->pressure_pa, capture.pressure_pa);
        const CubeRootCrossing local = fit_cube_root_crossing(near, previous->pressure_pa, capture.pressure_pa);
        crossing.low_pa = std::min(local.low_pa, crossing.pressure_pa);
        crossing.high_pa = std::max(local.high_pa, crossing.pressure_pa);
        crossing.scatter_mm = local.scatter_mm;
        const double area_m2 = session.device.rows * session.device.cols * std::pow(session.device.cell_size_mm / 1000.0, 2);
        out.pressure_pa = crossing.pressure_pa;
        out.mass_kg = out.pressure_pa * area_m2 / gravity;
        out.pressure_low_pa = crossing.low_pa;
        out.pressure_high_pa = crossing.high_pa;
        out.mass_low_kg = crossing.low_pa * area_m2 / gravity;
        out.mass_high_kg = crossing.high_pa * area_m2 / gravity;
        out.points = static_cast<int>(near.size());
        out.scatter_mm = crossing.scatter_mm;
        out.session = session.name;
        out.below_pa = previous->pressure_pa;
        out.above_pa = capture.pressure_pa;
        return out;
      }
      previous = &capture;
      previous_h = h;
    }
  }
  return out;
}

}  // namespace hj
