#include "sim/stiffness_matrix.h"

#include <cassert>
#include <cstdlib>
#include <stdexcept>

namespace hj {

namespace {

// Records which stencil slots of which points a force model touches.
class PatternRecorder final : public StiffnessSink {
 public:
  PatternRecorder(int num_points, int point_cols) : used_(static_cast<size_t>(num_points) * 25, 0), nc_(point_cols) {}
  void add(int row_point, int col_point, const Eigen::Matrix3d&) override {
    const int di = col_point / nc_ - row_point / nc_, dj = col_point % nc_ - row_point % nc_;
    if (std::abs(di) + std::abs(dj) > 2)
      throw std::logic_error("a stiffness block couples points further apart than the stencil allows");
    used_[static_cast<size_t>(row_point) * 25 + (di + 2) * 5 + (dj + 2)] = 1;
  }
  bool used(int point, int slot) const { return used_[static_cast<size_t>(point) * 25 + slot]; }

 private:
  std::vector<char> used_;
  int nc_;
};

}  // namespace

StiffnessMatrix::StiffnessMatrix(const Mesh& mesh, const std::vector<char>& fixed,
                                 const std::function<void(StiffnessSink&)>& touch)
    : point_cols_(mesh.point_cols()), dof_of_point_(mesh.num_points(), -1) {
  int n = 0;
  for (int p = 0; p < mesh.num_points(); ++p) {
    row_of_point_.push_back(mesh.row_of(p));
    col_of_point_.push_back(mesh.col_of(p));
  }
  for (int p = 0; p < mesh.num_points(); ++p)
    if (!fixed[p]) {
      dof_of_point_[p] = n;
      n += 3;
      free_points_.push_back(p);
    }
  PatternRecorder recorder(mesh.num_points(), mesh.point_cols());
  touch(recorder);
  // Build the pattern from triplets, then look up each entry's position.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(free_points_.size() * 13 * 9);
  auto for_each_pair = [&](auto&& fn) {
    for (int p : free_points_) {
      const int i = mesh.row_of(p), j = mesh.col_of(p);
      for (int di = -2; di <= 2; ++di)
        for (int dj = -2; dj <= 2; ++dj) {
          if (std::abs(di) + std::abs(dj) > 2) continue;
          if (!(di == 0 && dj == 0) && !recorder.used(p, (di + 2) * 5 + (dj + 2))) continue;
          const int qi = i + di, qj = j + dj;
          if (qi < 0 || qj < 0 || qi >= mesh.point_rows() || qj >= mesh.point_cols()) continue;
          const int q = mesh.index(qi, qj);
          if (!fixed[q]) fn(p, q);
        }
    }
  };
  for_each_pair([&](int p, int q) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) triplets.emplace_back(dof_of_point_[p] + r, dof_of_point_[q] + c, 0.0);
  });
  matrix_.resize(n, n);
  matrix_.setFromTriplets(triplets.begin(), triplets.end());
  matrix_.makeCompressed();
  value_index_.assign(static_cast<size_t>(mesh.num_points()) * kStencil * kStencil * 3, -1);
  for_each_pair([&](int p, int q) {
    for (int c = 0; c < 3; ++c) {
      const int row = dof_of_point_[p], col = dof_of_point_[q] + c;
      const int* begin = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col];
      const int* end = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col + 1];
      const int* hit = std::lower_bound(begin, end, row);
      if (end - hit < 3 || hit[1] != row + 1 || hit[2] != row + 2)
        throw std::logic_error("the stiffness pattern is not made of whole 3 x 3 blocks");
      value_index_[(static_cast<size_t>(p) * 25 + slot(p, q)) * 3 + c] = static_cast<int>(hit - matrix_.innerIndexPtr());
    }
  });
}

int StiffnessMatrix::slot(int row_point, int col_point) const {
  const int di = row_of_point_[col_point] - row_of_point_[row_point];
  const int dj = col_of_point_[col_point] - col_of_point_[row_point];
  assert(std::abs(di) + std::abs(dj) <= 2);
  return (di + 2) * kStencil + (dj + 2);
}

void StiffnessMatrix::set_zero() {
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
}

void StiffnessMatrix::add(int row_point, int col_point, const Eigen::Matrix3d& block) {
  if (dof_of_point_[row_point] < 0 || dof_of_point_[col_point] < 0) return;
  const int* idx = &value_index_[(static_cast<size_t>(row_point) * 25 + slot(row_point, col_point)) * 3];
  if (idx[0] < 0) throw std::logic_error("a stiffness block outside the pattern recorded for this settle");
  double* values = matrix_.valuePtr();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) values[idx[c] + r] += block(r, c);
}

Eigen::VectorXd StiffnessMatrix::gather(const Eigen::Matrix3Xd& field) const {
  Eigen::VectorXd out(num_dofs());
  for (int p : free_points_) out.segment<3>(dof_of_point_[p]) = field.col(p);
  return out;
}

Eigen::Matrix3Xd StiffnessMatrix::scatter(const Eigen::VectorXd& dofs) const {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, static_cast<int>(dof_of_point_.size()));
  for (int p : free_points_) out.col(p) = dofs.segment<3>(dof_of_point_[p]);
  return out;
}

}  // namespace hj
