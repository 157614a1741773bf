#include "sim/shifted_solver.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>

#include "sim/band_lu.h"

namespace hj {

namespace {

// Small systems factor in well under a millisecond: no point iterating.
constexpr Eigen::Index kMinIterativeDofs = 1500;
// BiCGSTAB budget; two matrix products an iteration. Past it the LU is
// cheaper on the sizes above.
constexpr int kMaxIterations = 40;
// Relative residual of the iterative solve: the Newton iteration corrects
// the rest (an inexact Newton step).
constexpr double kTolerance = 1e-8;
// Below this shift, as a fraction of the mean |diagonal| of K + mu I, the
// Jacobi-preconditioned iteration does not converge within its budget (on
// a 9 x 12 settle it converged at 0.07 and ran out at 0.022 and below), so
// it is not tried: each failure is 40 iterations thrown away before the LU.
constexpr double kMinIterativeShift = 0.05;

}  // namespace

struct ShiftedSolver::Direct {
  BandLU band;                                       // small systems (band_lu.h)
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;  // the rest
  bool analysed = false;
  bool use_band = false;
};

ShiftedSolver::ShiftedSolver() : direct_(std::make_unique<Direct>()) {
  // No iterative refinement: the Newton iteration itself corrects the step.
  direct_->lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
}

ShiftedSolver::~ShiftedSolver() = default;

bool ShiftedSolver::solve(const Eigen::SparseMatrix<double>& a, double mu, const Eigen::VectorXd& r,
                          Eigen::VectorXd& dx) {
  if (a.rows() >= kMinIterativeDofs && mu > 2.0 * failed_mu_ &&
      mu >= kMinIterativeShift * a.diagonal().cwiseAbs().mean()) {
    Eigen::BiCGSTAB<Eigen::SparseMatrix<double>, Eigen::DiagonalPreconditioner<double>> bicg;
    bicg.setMaxIterations(kMaxIterations);
    bicg.setTolerance(kTolerance);
    bicg.compute(a);
    dx = bicg.solve(r);
    if (bicg.info() == Eigen::Success && dx.allFinite()) {
      ++iterative_solves_;
      last_direct_ = false;
      return true;
    }
    failed_mu_ = mu;
  }
  if (!direct_->analysed) {
    direct_->band.analyze(a);
    direct_->use_band = direct_->band.worthwhile();
    if (!direct_->use_band) direct_->lu.analyzePattern(a);
    direct_->analysed = true;
  }
  if (direct_->use_band) {
    if (!direct_->band.factorize(a)) return false;
    direct_->band.solve(r, dx);
  } else {
    direct_->lu.factorize(a);
    if (direct_->lu.info() != Eigen::Success) return false;
    dx = direct_->lu.solve(r);
  }
  ++direct_solves_;
  last_direct_ = true;
  return dx.allFinite();
}

bool ShiftedSolver::solve_again(const Eigen::SparseMatrix<double>& a, double mu, const Eigen::VectorXd& r,
                                Eigen::VectorXd& dx) {
  if (!last_direct_) return solve(a, mu, r, dx);  // iterations are cheap
  if (direct_->use_band)
    direct_->band.solve(r, dx);
  else
    dx = direct_->lu.solve(r);
  return dx.allFinite();
}

}  // namespace hj
