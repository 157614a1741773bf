// Whether a static equilibrium is stable: the test the static solver runs
// before it accepts one. Pressure follows the normals, so the stiffness
// K = -dF/dx is not symmetric. sym(K) positive definite proves stability
// (for any eigenpair Re(lambda) = v* sym(K) v / |v|^2 > 0), but a negative
// eigenvalue of sym(K) need not be one of K's (a 9 x 12 dome at 2 kPa that
// the explicit dynamics settle on has 11), so the test then turns to K
// itself: a real negative eigenvalue is a direction the surface diverges
// along (a saddle, or the creased net near levelling).
#pragma once

#include <Eigen/SparseCore>

namespace hj {

// A unit real eigenvector of `stiffness` (square, over the free DOFs) whose
// eigenvalue is negative and nearest zero; empty when there is none.
Eigen::VectorXd divergence_mode(const Eigen::SparseMatrix<double>& stiffness);

}  // namespace hj
