// SuiteSparse's AMD as the stability check's LDL^T ordering
// (sim/amd_ordering.h): a permutation, with less fill than the mesh's band,
// and the same inertia (Sylvester) as the natural order.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <vector>

#include "sim/amd_ordering.h"

namespace hj {
namespace {

// The 5-point Laplacian of an n x n grid, shifted by -shift: indefinite
// once shift exceeds its smallest eigenvalue.
Eigen::SparseMatrix<double> grid_laplacian(int n, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  const auto at = [n](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      t.emplace_back(at(i, j), at(i, j), 4.0 - shift);
      if (i + 1 < n) t.emplace_back(at(i, j), at(i + 1, j), -1.0), t.emplace_back(at(i + 1, j), at(i, j), -1.0);
      if (j + 1 < n) t.emplace_back(at(i, j), at(i, j + 1), -1.0), t.emplace_back(at(i, j + 1), at(i, j), -1.0);
    }
  Eigen::SparseMatrix<double> a(n * n, n * n);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

template <typename Ordering>
using Ldlt = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Ordering>;

TEST(AmdOrdering, IsAPermutationThatCutsTheBandsFill) {
  const Eigen::SparseMatrix<double> a = grid_laplacian(40, 0.0);
  SuiteSparseAmdOrdering::PermutationType perm;
  SuiteSparseAmdOrdering()(a, perm);
  std::vector<char> seen(a.rows(), 0);
  for (int k = 0; k < perm.size(); ++k) {
    ASSERT_GE(perm.indices()(k), 0);
    ASSERT_LT(perm.indices()(k), a.rows());
    seen[perm.indices()(k)] = 1;
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), a.rows());
  const Ldlt<SuiteSparseAmdOrdering> amd(a);
  const Ldlt<Eigen::NaturalOrdering<int>> band(a);
  ASSERT_EQ(amd.info(), Eigen::Success);
  EXPECT_LT(amd.matrixL().nestedExpression().nonZeros(), band.matrixL().nestedExpression().nonZeros() / 2);
}

TEST(AmdOrdering, KeepsTheInertiaOfAnIndefiniteMatrix) {
  for (const double shift : {0.0, 0.037, 0.41, 1.73}) {
    const Eigen::SparseMatrix<double> a = grid_laplacian(20, shift);
    const Ldlt<SuiteSparseAmdOrdering> amd(a);
    const Ldlt<Eigen::NaturalOrdering<int>> band(a);
    ASSERT_EQ(amd.info(), Eigen::Success);
    ASSERT_EQ(band.info(), Eigen::Success);
    EXPECT_EQ((amd.vectorD().array() < 0.0).count(), (band.vectorD().array() < 0.0).count()) << "shift " << shift;
  }
}

}  // namespace
}  // namespace hj
