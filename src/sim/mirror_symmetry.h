// The mirror symmetry of a device state, and the subspace of displacements
// that keep it. The mesh is symmetric about its two centre lines, so a
// state whose positions, clamped and pinned points, jammed cells and forces
// are unchanged by a mirror (a free net under uniform pressure, from rest
// or from its mirrored sag) has an equilibrium with the same symmetry, and
// Newton steps from a symmetric state stay symmetric. The static solver
// can then settle it on the symmetric displacements alone: a quarter of the
// unknowns under both mirrors, a half under one, and a factorisation of
// their stiffness a fifth to a half of the full one's cost (9 x 12, p = 4:
// 4,935 unknowns, 1,254 symmetric ones). Whether the equilibrium is stable
// is a question about every displacement, symmetric or not, so the settle
// checks it on the full system afterwards (static_solver.cc).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "sim/force_model.h"
#include "sim/stiffness_matrix.h"

namespace hj {

// A subgroup of the mesh's mirror group {identity, mirror in x (columns j
// -> C - 1 - j), mirror in y (rows i -> R - 1 - i), both}: element g is the
// bit pattern (flips x) | (flips y) << 1, and `elements` has bit g set for
// each g in it. The identity (bit 0) is always in.
struct MirrorGroup {
  unsigned elements = 1;

  bool has(int g) const { return (elements >> g) & 1u; }
  // Elements other than the identity (0, 1 or 3).
  int order() const;
  bool trivial() const { return elements == 1u; }
};

// The orthogonal projection of a displacement field u (3 x N) onto the
// fields that `group` maps onto themselves times the character `odd` (bit
// g set: element g maps the field onto minus itself; a character, so odd
// must be closed as one: 0, or the bits of an element and of the other
// one it is composed with). Fixed points get 0.
Eigen::Matrix3Xd mirror_projection(const Mesh& mesh, const Eigen::Matrix3Xd& u, MirrorGroup group, unsigned odd,
                                   const std::vector<char>& fixed);

// Positions x with the displacements of the points not `fixed` from the
// flat grid averaged over their images under `group` (the orthogonal
// projection onto the symmetric displacements); fixed points unchanged.
Eigen::Matrix3Xd mirror_average(const Mesh& mesh, const Eigen::Matrix3Xd& x, MirrorGroup group,
                                const std::vector<char>& fixed);

// The characters of `group` as `odd` masks: the symmetric one (0) first.
std::vector<unsigned> mirror_characters(MirrorGroup group);

// The character whose displacements hold the largest part of field u, and
// the norm of that part (mirror_projection).
struct MirrorClass {
  unsigned odd = 0;
  double norm = 0.0;
};
MirrorClass strongest_mirror_class(const Mesh& mesh, const Eigen::Matrix3Xd& u, MirrorGroup group,
                                   const std::vector<char>& fixed);

// The elements of `group` that a field of character `odd` is symmetric under.
inline MirrorGroup mirror_kernel(MirrorGroup group, unsigned odd) { return {group.elements & ~odd}; }

// The largest subgroup under which `state` is symmetric for `model`: the
// clamped and pinned points and jammed cells map onto themselves, the
// displacements from the flat grid onto their mirror images within
// `position_tolerance_m`, the forces at the symmetrised positions onto
// theirs within 1e-9 of the largest one plus k h, and the stiffness there
// onto its mirror image within 1e-9 of its largest entry. One force and
// one stiffness evaluation.
MirrorGroup mirror_symmetry_of(const ForceModel& model, const DeviceState& state,
                               double position_tolerance_m = 1e-9);

// The displacements of the free points that `group` maps onto themselves
// (times the character `odd`, see mirror_projection; 0: unchanged): one
// unknown per orbit of (point, component), with the component zero where a
// mirror that fixes the point flips it. S maps the unknowns to the free
// DOFs of `full` (entries +-1); the settle solves S^T (K + mu I) S dy =
// S^T F and moves by S dy. At a symmetric state K maps each character's
// displacements onto themselves, so its eigenvectors lie in one each.
class MirrorSubspace {
 public:
  // `full` gives the free DOFs and the stiffness pattern; the subspace keeps
  // a reference to it, which must outlive it. `fixed` must be symmetric.
  MirrorSubspace(const Mesh& mesh, const StiffnessMatrix& full, MirrorGroup group, unsigned odd = 0);
  MirrorSubspace(const Mesh&, StiffnessMatrix&&, MirrorGroup, unsigned = 0) = delete;

  int num_dofs() const { return num_dofs_; }
  // S^T of a point field (forces): its free points summed over each orbit.
  Eigen::VectorXd gather(const Eigen::Matrix3Xd& field) const;
  // S y as a point field (displacements); fixed points get 0.
  Eigen::Matrix3Xd scatter(const Eigen::VectorXd& dofs) const;
  // Diagonal of S^T S: how many free DOFs share each unknown.
  const Eigen::VectorXd& weights() const { return weights_; }

  // An empty matrix with the pattern of S^T K S.
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  // reduced = S^T K S for the values of `full`'s matrix now (reduced has
  // pattern()'s pattern).
  void reduce(Eigen::SparseMatrix<double>& reduced) const;

 private:
  const StiffnessMatrix& full_;
  int num_points_;
  int num_dofs_ = 0;
  // Per free DOF of `full`: its unknown (-1: held at zero) and sign.
  std::vector<int> unknown_of_dof_;
  std::vector<signed char> sign_of_dof_;
  Eigen::VectorXd weights_;
  Eigen::SparseMatrix<double> pattern_;
  // Per stored entry of `full`'s matrix: its position in the reduced values
  // (-1: dropped) and sign.
  std::vector<int> entry_target_;
  std::vector<signed char> entry_sign_;
};

}  // namespace hj
