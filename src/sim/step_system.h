// The linear system of one static-solver step, (K + mu I) dx = F over the
// free DOFs, or S^T (K + mu I) S dy = S^T F over a mirror subspace
// (mirror_symmetry.h), with K assembled once per position and the shift
// changed without assembling it again (the careful control refuses about a
// third of its steps on stiff jammed cells, and only mu changes there).
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "sim/force_model.h"
#include "sim/mirror_symmetry.h"
#include "sim/stiffness_matrix.h"

namespace hj {

class StepSystem {
 public:
  // Over every free DOF of `k`.
  explicit StepSystem(StiffnessMatrix& k);
  // Over `subspace` of k's DOFs. Both are kept by reference.
  StepSystem(StiffnessMatrix& k, const MirrorSubspace& subspace);

  int num_dofs() const { return static_cast<int>(weights_.size()); }
  // Forces (3 x N) to the right-hand side.
  Eigen::VectorXd gather(const Eigen::Matrix3Xd& forces) const;
  // A solution to displacements (3 x N; fixed points 0).
  Eigen::Matrix3Xd scatter(const Eigen::VectorXd& step) const;
  // |F| of the forces whose right-hand side is r: on a subspace, where r
  // sums each orbit's forces, sqrt(r^T W^-1 r), so that the step controls
  // see the same residual as on the full system.
  double force_norm(const Eigen::VectorXd& r) const;

  // K at positions x, kept unshifted for set_shift().
  void assemble(const ForceModel& model, const DeviceState& state, const Eigen::Matrix3Xd& x);
  // matrix() = K + mu W (W = I, or S^T S on a subspace) with the K of the
  // last assemble(). Exactly K's values plus mu on the diagonal.
  void set_shift(double mu);
  const Eigen::SparseMatrix<double>& matrix() const { return subspace_ ? reduced_ : k_.matrix(); }

 private:
  StiffnessMatrix& k_;
  const MirrorSubspace* subspace_ = nullptr;
  Eigen::SparseMatrix<double> reduced_;
  Eigen::VectorXd unshifted_;
  std::vector<Eigen::Index> diagonal_;  // position of each diagonal entry in matrix()'s values
  Eigen::VectorXd weights_;
};

}  // namespace hj
