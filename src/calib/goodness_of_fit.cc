#include "calib/goodness_of_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hj {

double chi_square_upper_tail(double chi2, double dof) {
  if (!(dof > 0.0)) return 1.0;
  if (!(chi2 > 0.0)) return 1.0;
  const double v = 2.0 / (9.0 * dof);
  const double z = (std::cbrt(chi2 / dof) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

GoodnessOfFit goodness_of_fit(const LeastSquaresResult& fit, double noise_floor_mm, const GoodnessOfFitOptions& options) {
  GoodnessOfFit g;
  g.rmse_mm = fit.rmse_mm;
  g.noise_floor_mm = noise_floor_mm;
  g.dof = std::max(fit.residual_count - fit.free_parameters, 1L);
  const double floor2 = noise_floor_mm * noise_floor_mm;
  g.chi2 = floor2 > 0.0 ? fit.sum_sq_mm2 / floor2 : std::numeric_limits<double>::infinity();
  g.p_value = chi_square_upper_tail(g.chi2, static_cast<double>(g.dof));
  g.systematic_mm = std::sqrt(std::max(0.0, fit.rmse_mm * fit.rmse_mm - floor2));
  g.explained = g.p_value >= options.alpha || fit.rmse_mm <= (1.0 + options.floor_tolerance) * noise_floor_mm;
  return g;
}

}  // namespace hj
