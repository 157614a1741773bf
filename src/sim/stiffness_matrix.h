// The stiffness K = -dF/dx over the free degrees of freedom (3 per free
// point) as an Eigen sparse matrix whose pattern is fixed for a set of fixed
// points, so each Newton step only refills values and refactorises.
#pragma once

#include <Eigen/SparseCore>
#include <functional>
#include <vector>

#include "sim/effect.h"

namespace hj {

class StiffnessMatrix final : public StiffnessSink {
 public:
  // The pattern holds the diagonal and every block that `touch` adds to a
  // sink: run the force model's add_stiffness there, so the pattern is as
  // sparse as the active effects (5 blocks a row unjammed, 13 jammed).
  StiffnessMatrix(const Mesh& mesh, const std::vector<char>& fixed,
                  const std::function<void(StiffnessSink&)>& touch);

  int num_dofs() const { return static_cast<int>(matrix_.rows()); }
  // Free DOF of (point, component), -1 for a fixed point.
  int dof(int point, int component) const { return dof_of_point_[point] < 0 ? -1 : dof_of_point_[point] + component; }
  const std::vector<int>& free_points() const { return free_points_; }

  void set_zero();
  void add(int row_point, int col_point, const Eigen::Matrix3d& block) override;
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }
  Eigen::SparseMatrix<double>& matrix() { return matrix_; }

  // Free-DOF vector <-> (3 x N) point field (fixed points get 0).
  Eigen::VectorXd gather(const Eigen::Matrix3Xd& field) const;
  Eigen::Matrix3Xd scatter(const Eigen::VectorXd& dofs) const;

 private:
  static constexpr int kStencil = 5;  // di, dj in -2..2
  int slot(int row_point, int col_point) const;

  int point_cols_;
  // Each point's mesh row and column, so that slot() needs no division (it
  // runs 25 times per bending spring in every Newton step).
  std::vector<int> row_of_point_, col_of_point_;
  std::vector<int> dof_of_point_;
  std::vector<int> free_points_;
  // value_index_[(row_point * 25 + slot) * 3 + c]: position in
  // matrix_.valuePtr() of the block's column c, row 0 (rows 1 and 2 follow:
  // the pattern is made of whole 3 x 3 blocks); -1 where the row or column
  // point is fixed. One index per column, not per entry, keeps the table
  // small enough to stay in cache while a step's stiffness is added.
  std::vector<int> value_index_;
  Eigen::SparseMatrix<double> matrix_;
};

}  // namespace hj
