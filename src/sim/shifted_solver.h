// Solves the regularised Newton system (K + mu I) dx = r of the static
// solver. While mu is large (the damped, flow-like start of a settle) the
// shifted matrix is diagonally dominant and Jacobi-preconditioned BiCGSTAB
// converges in a few dozen products, an order of magnitude cheaper than a
// sparse LU on a 9 x 12 array; as mu falls towards Newton it stops
// converging within its budget and the solve switches to a direct LU
// (factorised only when needed): the band LU on small arrays (band_lu.h),
// UMFPACK's otherwise.
#pragma once

#include <Eigen/SparseCore>
#include <memory>

namespace hj {

class ShiftedSolver {
 public:
  ShiftedSolver();
  ~ShiftedSolver();
  ShiftedSolver(const ShiftedSolver&) = delete;
  ShiftedSolver& operator=(const ShiftedSolver&) = delete;

  // a = K + mu I over the free DOFs (pattern fixed between calls). Returns
  // false if no solve succeeded (a singular a); dx is then unspecified.
  bool solve(const Eigen::SparseMatrix<double>& a, double mu, const Eigen::VectorXd& r, Eigen::VectorXd& dx);

  // Solves with the matrix of the last successful solve() again (a second
  // right-hand side): the LU is reused, not refactorised.
  bool solve_again(const Eigen::SparseMatrix<double>& a, double mu, const Eigen::VectorXd& r, Eigen::VectorXd& dx);

  int iterative_solves() const { return iterative_solves_; }
  int direct_solves() const { return direct_solves_; }

 private:
  struct Direct;
  std::unique_ptr<Direct> direct_;
  // The smallest mu at which the iterative solve last failed: below it (and
  // a little above) go straight to the LU.
  double failed_mu_ = 0.0;
  bool last_direct_ = false;
  int iterative_solves_ = 0;
  int direct_solves_ = 0;
};

}  // namespace hj
