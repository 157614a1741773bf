#include "sim/divergence_mode.h"

#include <Eigen/SparseCholesky>
#include <Eigen/UmfPackSupport>
#include <cmath>

namespace hj {

Eigen::VectorXd divergence_mode(const Eigen::SparseMatrix<double>& stiffness) {
  const Eigen::SparseMatrix<double> sym = 0.5 * (stiffness + Eigen::SparseMatrix<double>(stiffness.transpose()));
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(sym);
  if (ldlt.info() == Eigen::Success) {
    const Eigen::VectorXd d = ldlt.vectorD();
    // Without pivoting, the signs of D are the signs of the eigenvalues
    // (Sylvester's law of inertia).
    if (d.minCoeff() > 1e-12 * d.cwiseAbs().maxCoeff()) return {};
  }
  // Inverse iteration on K for its eigenvalue nearest zero, shifted
  // slightly so a singular K still factors.
  const double scale = sym.diagonal().cwiseAbs().maxCoeff();
  Eigen::SparseMatrix<double> shifted = stiffness;
  for (int i = 0; i < shifted.rows(); ++i) shifted.coeffRef(i, i) += 1e-9 * scale;
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
  lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
  lu.compute(shifted);
  if (lu.info() != Eigen::Success) return {};
  // Start mostly out of plane (where the net creases), in plane a little.
  Eigen::VectorXd v = Eigen::VectorXd::Constant(sym.rows(), 0.1);
  for (int i = 2; i < v.size(); i += 3) v(i) = 1.0;
  for (int it = 0; it < 40; ++it) {
    Eigen::VectorXd next = lu.solve(v);
    if (!next.allFinite() || next.norm() == 0.0) return {};
    v = next.normalized();
  }
  const Eigen::VectorXd kv = stiffness * v;
  const double lambda = v.dot(kv);
  // A real eigenpair (a complex pair does not converge: no divergence).
  if (lambda > -1e-9 * scale || (kv - lambda * v).norm() > 1e-3 * std::abs(lambda)) return {};
  return v;
}

}  // namespace hj
