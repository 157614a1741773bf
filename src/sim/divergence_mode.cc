#include "sim/divergence_mode.h"

#include <Eigen/SparseCholesky>
#include <Eigen/UmfPackSupport>
#include <cmath>
#include <optional>

#include "sim/amd_ordering.h"

namespace hj {

namespace {

constexpr int kInverseIterations = 40;

}  // namespace

struct DivergenceSearch::Factors {
  double scale = 0.0;  // largest |diagonal| of K
  std::optional<bool> sym_positive_definite;
  std::optional<bool> lu_ok;
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
};

DivergenceSearch::DivergenceSearch(const Eigen::SparseMatrix<double>& stiffness)
    : stiffness_(stiffness), factors_(std::make_unique<Factors>()) {
  factors_->scale = stiffness.diagonal().cwiseAbs().maxCoeff();
}

DivergenceSearch::~DivergenceSearch() = default;

namespace {

// One step of inverse iteration; false if the solve breaks down.
bool inverse_step(const Eigen::UmfPackLU<Eigen::SparseMatrix<double>>& lu, Eigen::VectorXd& v) {
  Eigen::VectorXd next = lu.solve(v);
  if (!next.allFinite() || next.norm() == 0.0) return false;
  v = next.normalized();
  return true;
}

// The eigenvalue if v is a real eigenvector with a negative one (within the
// tolerances mode() has always used), else nothing.
std::optional<double> negative_eigenvalue(const Eigen::SparseMatrix<double>& k, const Eigen::VectorXd& v,
                                          double scale) {
  const Eigen::VectorXd kv = k * v;
  const double lambda = v.dot(kv);
  // A real eigenpair (a complex pair does not converge: no divergence).
  if (lambda > -1e-9 * scale || (kv - lambda * v).norm() > 1e-3 * std::abs(lambda)) return std::nullopt;
  return lambda;
}

}  // namespace

bool DivergenceSearch::sym_positive_definite() {
  Factors& f = *factors_;
  if (!f.sym_positive_definite) {
    const Eigen::SparseMatrix<double> sym = 0.5 * (stiffness_ + Eigen::SparseMatrix<double>(stiffness_.transpose()));
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, SuiteSparseAmdOrdering> ldlt(sym);
    f.sym_positive_definite = false;
    if (ldlt.info() == Eigen::Success) {
      const Eigen::VectorXd d = ldlt.vectorD();
      // Without pivoting, the signs of D are the signs of the eigenvalues
      // (Sylvester's law of inertia), in any symmetric order.
      f.sym_positive_definite = d.minCoeff() > 1e-12 * d.cwiseAbs().maxCoeff();
    }
  }
  return *f.sym_positive_definite;
}

bool DivergenceSearch::factorize() {
  Factors& f = *factors_;
  if (!f.lu_ok) {
    // Inverse iteration on K for its eigenvalue nearest zero, shifted
    // slightly so a singular K still factors.
    Eigen::SparseMatrix<double> shifted = stiffness_;
    for (int i = 0; i < shifted.rows(); ++i) shifted.coeffRef(i, i) += 1e-9 * f.scale;
    f.lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
    f.lu.compute(shifted);
    f.lu_ok = f.lu.info() == Eigen::Success;
  }
  return *f.lu_ok;
}

Eigen::VectorXd DivergenceSearch::mode() {
  if (sym_positive_definite() || !factorize()) return {};
  // Start mostly out of plane (where the net creases), in plane a little.
  Eigen::VectorXd v = Eigen::VectorXd::Constant(stiffness_.rows(), 0.1);
  for (int i = 2; i < v.size(); i += 3) v(i) = 1.0;
  for (int it = 0; it < kInverseIterations; ++it)
    if (!inverse_step(factors_->lu, v)) return {};
  if (!negative_eigenvalue(stiffness_, v, factors_->scale)) return {};
  return v;
}

bool DivergenceSearch::still_has(const Eigen::VectorXd& known, double overlap) {
  const Factors& f = *factors_;
  if (known.size() != stiffness_.rows() || (f.sym_positive_definite && *f.sym_positive_definite)) return false;
  // No LDL^T first: where sym(K) is positive definite every v K v > 0, so
  // no negative eigenpair is found and the answer is false all the same.
  if (!factorize()) return false;
  Eigen::VectorXd v = known;
  for (int it = 0; it < kInverseIterations; ++it) {
    if (!inverse_step(f.lu, v)) return false;
    if (negative_eigenvalue(stiffness_, v, f.scale)) return std::abs(v.dot(known)) > overlap;
  }
  return false;
}

Eigen::VectorXd divergence_mode(const Eigen::SparseMatrix<double>& stiffness) {
  return DivergenceSearch(stiffness).mode();
}

}  // namespace hj
