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
#include <memory>

namespace hj {

// A unit real eigenvector of `stiffness` (square, over the free DOFs) whose
// eigenvalue is negative and nearest zero; empty when there is none.
Eigen::VectorXd divergence_mode(const Eigen::SparseMatrix<double>& stiffness);

// The same search in parts, each factorisation made once and only when a
// question needs it (an LDL^T of sym(K), an LU of K), so that a settle
// that already knows a mode (SettleMemory) can ask about it first.
class DivergenceSearch {
 public:
  // `stiffness` is read, not copied: it must outlive the search.
  explicit DivergenceSearch(const Eigen::SparseMatrix<double>& stiffness);
  DivergenceSearch(Eigen::SparseMatrix<double>&&) = delete;
  ~DivergenceSearch();

  // The divergence_mode() of the stiffness.
  Eigen::VectorXd mode();
  // True if K has a real eigenpair with a negative eigenvalue whose unit
  // vector overlaps `known` (unit) by more than `overlap`, found by inverse
  // iteration from `known` (at most as many solves as mode() makes; the 9 x
  // 12 dome's shear mode, known from the coarse mesh: 3). Never true where
  // sym(K) is positive definite, and otherwise as mode() would decide when
  // `known` is the mode nearest zero.
  bool still_has(const Eigen::VectorXd& known, double overlap);

 private:
  struct Factors;
  bool sym_positive_definite();  // LDL^T of sym(K), once
  bool factorize();              // LU of K shifted by 1e-9 of its diagonal, once
  const Eigen::SparseMatrix<double>& stiffness_;
  std::unique_ptr<Factors> factors_;
};

}  // namespace hj
