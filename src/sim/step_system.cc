#include "sim/step_system.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hj {

namespace {

std::vector<Eigen::Index> diagonal_positions(const Eigen::SparseMatrix<double>& a) {
  std::vector<Eigen::Index> out(a.cols());
  for (int col = 0; col < a.cols(); ++col) {
    const int* begin = a.innerIndexPtr() + a.outerIndexPtr()[col];
    const int* end = a.innerIndexPtr() + a.outerIndexPtr()[col + 1];
    const int* hit = std::lower_bound(begin, end, col);
    if (hit == end || *hit != col) throw std::logic_error("StepSystem: the pattern lacks a diagonal entry");
    out[col] = hit - a.innerIndexPtr();
  }
  return out;
}

}  // namespace

StepSystem::StepSystem(StiffnessMatrix& k)
    : k_(k), diagonal_(diagonal_positions(k.matrix())), weights_(Eigen::VectorXd::Ones(k.num_dofs())) {}

StepSystem::StepSystem(StiffnessMatrix& k, const MirrorSubspace& subspace)
    : k_(k),
      subspace_(&subspace),
      reduced_(subspace.pattern()),
      diagonal_(diagonal_positions(subspace.pattern())),
      weights_(subspace.weights()) {}

Eigen::VectorXd StepSystem::gather(const Eigen::Matrix3Xd& forces) const {
  return subspace_ ? subspace_->gather(forces) : k_.gather(forces);
}

Eigen::Matrix3Xd StepSystem::scatter(const Eigen::VectorXd& step) const {
  return subspace_ ? subspace_->scatter(step) : k_.scatter(step);
}

double StepSystem::force_norm(const Eigen::VectorXd& r) const {
  return subspace_ ? std::sqrt(r.cwiseAbs2().cwiseQuotient(weights_).sum()) : r.norm();
}

void StepSystem::assemble(const ForceModel& model, const DeviceState& state, const Eigen::Matrix3Xd& x) {
  k_.set_zero();
  model.add_stiffness(state, x, k_);
  if (subspace_) subspace_->reduce(reduced_);
  unshifted_ = matrix().coeffs();
}

void StepSystem::set_shift(double mu) {
  Eigen::SparseMatrix<double>& a = subspace_ ? reduced_ : k_.matrix();
  a.coeffs() = unshifted_;
  if (mu == 0.0) return;
  double* values = a.valuePtr();
  for (size_t i = 0; i < diagonal_.size(); ++i) values[diagonal_[i]] += mu * weights_[static_cast<Eigen::Index>(i)];
}

}  // namespace hj
