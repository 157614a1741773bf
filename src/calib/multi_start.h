// A candidate's refit must not depend on starting at the current model's
// optimum: where the baseline absorbed a strong effect into distorted
// parameters (a strong strain stiffening: k twice the truth, kappa_jam at
// its bound), a local fit from there stops near the effect's neutral value.
// So each new parameter in turn is started at points spanning its whole
// range (log-spaced for a range from zero or a positive bound, evenly
// otherwise), the others where the local fit left them, every parameter
// refitted jointly from each for a few iterations, and the full local refit
// starts from the best of them. Several parameters of one effect can trade
// off into a wrong basin (a strong cell_stiffness: the gradient found, the
// bulge left near 0 at a fifth of the truth), so each is started apart.
#pragma once

#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj {

struct MultiStartOptions {
  int starts = 4;      // values of each new parameter tried
  int iterations = 2;  // Levenberg-Marquardt iterations from each
};

struct StartTried {
  std::string parameter;  // qualified name of the parameter started
  double value = 0.0;     // its start
  double rmse_mm = 0.0;   // after the short joint fit; NaN if it did not replay
  double fitted = 0.0;    // that parameter where the short fit stopped
};

struct MultiStart {
  std::string parameter;  // qualified names of the parameters started over their ranges, comma-separated
  std::vector<StartTried> tried;
  ModelParams best;        // the short fit of lowest cost
  double best_sum_sq_mm2 = 0.0;
  bool found = false;      // some start replayed
};

// The start values of parameter `spec`: log-spaced from upper / 10^(starts-1)
// to upper when lower is 0 (bending's kappa_bend, stiffening's beta), from
// lower to upper when both are positive, evenly from lower to upper otherwise.
std::vector<double> range_starts(const ParameterSpec& spec, int starts);

// True for an effect multi_start() applies to: fitted parameters and
// forces on the surface (a camera effect is close to linear in its values).
bool wants_multi_start(const std::string& effect);

// @param start  the current model with `effect` switched on
MultiStart multi_start(const Dataset& dataset, const ModelParams& start, const std::vector<FitParameter>& parameters,
                       const std::string& effect, const LeastSquaresOptions& fit,
                       const MultiStartOptions& options = {});

}  // namespace hj
