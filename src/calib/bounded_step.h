// The Gauss-Newton step of a linearised least-squares problem with each
// step component held inside its bounds: min |r + J d|^2 over d with
// lo <= d <= hi. Solved by the free step, then each component beyond a
// bound held at it and the others solved again (one pass per component at
// most), with a little Levenberg damping so that an exactly flat direction
// stays finite. Used where a fit's linearisation predicts a refit: the
// screening's step, and the cross-validation folds' steps, where a
// parameter at its bound (kappa_jam at 100) must stay there as a bounded
// refit keeps it, not take the others with it on a move that is clamped.
#pragma once

#include <Eigen/Core>

namespace hj {

// lo, hi: per column, in the units of d (-inf / +inf: unbounded).
Eigen::VectorXd bounded_gauss_newton_step(const Eigen::MatrixXd& j, const Eigen::VectorXd& r,
                                          const Eigen::VectorXd& lo, const Eigen::VectorXd& hi);

}  // namespace hj
