#include "sim/amd_ordering.h"

#include <amd.h>

#include <vector>

namespace hj {

void SuiteSparseAmdOrdering::operator()(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& symmetric,
                                        PermutationType& perm) const {
  // AMD reads the compressed arrays; Eigen passes the pattern compressed.
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> copy;
  const auto* a = &symmetric;
  if (!symmetric.isCompressed()) {
    copy = symmetric;
    copy.makeCompressed();
    a = &copy;
  }
  const int n = static_cast<int>(a->rows());
  std::vector<int> order(n);
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  perm.resize(n);
  if (amd_order(n, a->outerIndexPtr(), a->innerIndexPtr(), order.data(), control, info) < AMD_OK) {
    perm.setIdentity();
    return;
  }
  // AMD's order[k] is the index of the k-th pivot; Eigen's factorisations
  // take the ordering as that map (new position -> old index).
  for (int k = 0; k < n; ++k) perm.indices()(k) = order[k];
}

}  // namespace hj
