// Does a model explain the data, or only less badly than the others? The
// test of its residuals against the sensor's noise model: each measured
// height is the true one plus Gaussian noise of the sensor's accuracy,
// rounded to its resolution, so a perfect model leaves residuals of
// variance floor^2 = accuracy^2 + resolution^2 / 12 (noise_floor_mm).
#pragma once

#include "calib/least_squares.h"

namespace hj {

struct GoodnessOfFitOptions {
  // The chi-square test rejects the noise model below this p-value.
  double alpha = 1e-3;
  // With 1e5 samples the test resolves a misfit of a few tenths of a
  // percent of the floor, finer than a sensor's stated accuracy is known;
  // an RMSE within this share of the floor (a systematic misfit under a
  // third of the noise) also counts as explained.
  double floor_tolerance = 0.05;
};

struct GoodnessOfFit {
  double rmse_mm = 0.0;
  double noise_floor_mm = 0.0;
  double chi2 = 0.0;  // SSR / floor^2
  long dof = 0;       // samples - free parameters
  double p_value = 1.0;  // P(chi2_dof >= chi2) if the residuals are the sensor's noise
  // The part of the RMSE the noise cannot account for, sqrt(max(0, RMSE^2 - floor^2)).
  double systematic_mm = 0.0;
  bool explained = false;  // p_value >= alpha, or RMSE within floor_tolerance of the floor
};

// Upper tail of the chi-square distribution with `dof` degrees of freedom
// (Wilson-Hilferty's cube-root normal approximation: for the 1e4..1e6
// degrees of freedom of a dataset its error is far below any alpha used).
double chi_square_upper_tail(double chi2, double dof);

GoodnessOfFit goodness_of_fit(const LeastSquaresResult& fit, double noise_floor_mm,
                              const GoodnessOfFitOptions& options = {});

}  // namespace hj
