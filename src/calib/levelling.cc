#include "calib/levelling.h"

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

// A net without pre-tension deflects as the cube root of its net load:
// h = a cbrt(P - P0). Over the session's unjammed, unpinned captures, P0 in
// [lo, hi] minimising the squared misfit (a in closed form for each P0).
double cube_root_crossing(const Session& session, const std::vector<MeasuredCapture>& captures, double lo, double hi) {
  std::vector<std::pair<double, double>> points;  // (P, h)
  for (const auto& c : captures) {
    if (c.jammed_count() > 0 || !c.pinned.empty()) continue;
    const double h = centre_height_mm(session, c);
    if (!std::isnan(h)) points.push_back({c.pressure_pa, h});
  }
  auto misfit = [&](double p0) {
    double sxy = 0.0, sxx = 0.0, syy = 0.0;
    for (auto [p, h] : points) {
      const double x = std::cbrt(p - p0);
      sxy += x * h;
      sxx += x * x;
      syy += h * h;
    }
    return sxx > 0.0 ? syy - sxy * sxy / sxx : syy;
  };
  double best = 0.5 * (lo + hi), best_misfit = misfit(best);
  constexpr int kSteps = 2000;
  for (int k = 0; k <= kSteps; ++k) {
    const double p0 = lo + (hi - lo) * k / kSteps;
    const double m = misfit(p0);
    if (m < best_misfit) best_misfit = m, best = p0;
  }
  return best;
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
        out.pressure_pa = cube_root_crossing(session, measured.captures, previous->pressure_pa, capture.pressure_pa);
        const double area_m2 = session.device.rows * session.device.cols * std::pow(session.device.cell_size_mm / 1000.0, 2);
        out.mass_kg = out.pressure_pa * area_m2 / gravity;
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
