// The stability check's question about a known divergence mode
// (DivergenceSearch::still_has) at a mirror-symmetric state, asked of the
// one symmetry class of displacements the mode lies in. There K maps each
// class onto itself (mirror_symmetry.h), so its eigenvectors lie in one
// class each, and the inverse iteration needs the LU of that class's block
// only: a quarter of the unknowns under both mirrors (9 x 12, p = 4: 1,213
// to 1,254 a class, of 4,935).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "sim/mirror_symmetry.h"
#include "sim/stiffness_matrix.h"

namespace hj {

// As DivergenceSearch(k.matrix()).still_has(known, overlap), k holding K
// at a state symmetric under `group`: true if K has a real eigenpair with a
// negative eigenvalue whose unit vector overlaps `known` (unit, over k's
// free DOFs) by more than `overlap`. False where no class holds more than
// `overlap` of `known` (no eigenvector can then overlap it that much);
// nothing where `group` is trivial (ask the full search).
std::optional<bool> still_has_in_mirror_class(const Mesh& mesh, const StiffnessMatrix& k, MirrorGroup group,
                                              const Eigen::VectorXd& known, double overlap);

}  // namespace hj
