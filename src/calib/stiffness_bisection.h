// The paper's Algorithm 1: one stiffness fitted by a modified bisection, the
// other parameters held. The simulated captures of the chosen kind are
// compared with the measured ones by their mean deflection from the level
// of the clamped edge, which falls as the stiffness rises; the bisection
// (on a log scale, as a stiffness spans decades) finds where the simulated
// mean deflection equals the measured one. "Modified": the bracket first
// grows from the start value by factors of 4 within the parameter's bounds.
#pragma once

#include <functional>
#include <string>

#include "calib/fit_parameters.h"
#include "calib/residuals.h"

namespace hj {

// Which captures constrain the stiffness.
using CaptureFilter = std::function<bool(const MeasuredCapture&)>;

struct BisectionOptions {
  int iterations = 12;  // halvings of the log bracket
  ReplayOptions replay = fitting_replay({});
};

struct BisectionResult {
  bool bracketed = false;  // the deflections crossed; else value = start
  double value = 0.0;
  int evaluations = 0;
  int captures = 0;        // that matched the filter
};

// Called after each evaluation: evaluations done, at most in all.
using BisectionProgress = std::function<void(int done, int total)>;

// @pre `parameter` is a stiffness of `start` (deflection falls as it rises).
BisectionResult fit_stiffness_by_bisection(const Dataset& dataset, const ModelParams& start,
                                           const FitParameter& parameter, const CaptureFilter& filter,
                                           const BisectionOptions& options, const BisectionProgress& progress = {});

}  // namespace hj
