// A fill-reducing ordering for Eigen's sparse Cholesky factorisations from
// SuiteSparse's AMD (the library UMFPACK orders with). The stiffness is
// banded in the mesh's order, but a band's fill on a 9 x 12 array is about
// four times AMD's (7.3e5 against 1.9e5 entries of L) and its LDL^T 4.5-5
// times slower; Eigen's own AMD port read past its buffer under ASan.
#pragma once

#include <Eigen/SparseCore>

namespace hj {

struct SuiteSparseAmdOrdering {
  using PermutationType = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
  // `symmetric`: the full pattern (both triangles), as Eigen's Cholesky
  // factorisations pass it. Sets `perm` to the pivot order. Falls back to
  // the natural order if AMD fails.
  void operator()(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& symmetric, PermutationType& perm) const;
};

}  // namespace hj
