#include "sim/symmetric_stability.h"

#include "sim/divergence_mode.h"

namespace hj {

std::optional<bool> still_has_in_mirror_class(const Mesh& mesh, const StiffnessMatrix& k, MirrorGroup group,
                                              const Eigen::VectorXd& known, double overlap) {
  if (group.trivial()) return std::nullopt;
  if (known.size() != k.num_dofs()) return false;
  std::vector<char> fixed(mesh.num_points(), 1);
  for (int p : k.free_points()) fixed[p] = 0;
  const Eigen::Matrix3Xd field = k.scatter(known);
  const MirrorClass best = strongest_mirror_class(mesh, field, group, fixed);
  if (!(best.norm > overlap)) return false;
  // The class's block in an orthonormal basis, Q = S W^-1/2: Q^T K Q has
  // K's eigenpairs in the class, and Q^T known is known's part in it.
  const MirrorSubspace subspace(mesh, k, group, best.odd);
  Eigen::SparseMatrix<double> block = subspace.pattern();
  subspace.reduce(block);
  const Eigen::VectorXd scale = subspace.weights().cwiseSqrt().cwiseInverse();
  block = scale.asDiagonal() * block * scale.asDiagonal();
  const Eigen::VectorXd part = scale.cwiseProduct(subspace.gather(field));
  const double norm = part.norm();
  if (!(norm > overlap)) return false;
  DivergenceSearch search(block);
  // |v . known| = |v . part| for v in the class.
  return search.still_has(part / norm, overlap / norm);
}

}  // namespace hj
