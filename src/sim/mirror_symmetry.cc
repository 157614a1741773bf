#include "sim/mirror_symmetry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hj {

namespace {

// The image of point p under element g.
int image(const Mesh& mesh, int g, int p) {
  const int i = mesh.row_of(p), j = mesh.col_of(p);
  return mesh.index((g & 2) ? mesh.point_rows() - 1 - i : i, (g & 1) ? mesh.point_cols() - 1 - j : j);
}

// D_g's entry for component c: a mirror in x flips x, one in y flips y.
int flip(int g, int c) { return (c == 0 && (g & 1)) || (c == 1 && (g & 2)) ? -1 : 1; }

// chi(g) of the character with odd elements `odd`.
double character(unsigned odd, int g) { return (odd >> g) & 1u ? -1.0 : 1.0; }

Eigen::Vector3d mirrored(int g, const Eigen::Vector3d& v) { return {flip(g, 0) * v.x(), flip(g, 1) * v.y(), v.z()}; }

// Clamped and pinned points and jammed cells map onto themselves under g.
bool pattern_symmetric(const Mesh& mesh, const DeviceState& state, const std::vector<char>& fixed, int g) {
  for (int p = 0; p < mesh.num_points(); ++p)
    if (fixed[p] != fixed[image(mesh, g, p)]) return false;
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c)
      if (state.jammed(mesh, r, c) !=
          state.jammed(mesh, (g & 2) ? mesh.rows() - 1 - r : r, (g & 1) ? mesh.cols() - 1 - c : c))
        return false;
  return true;
}

// Whether element g maps the point field u onto itself, D_g u(p) = u(g p),
// within `tolerance`, over the points not `skipped` (null: every point).
bool maps_onto_itself(const Mesh& mesh, const Eigen::Matrix3Xd& u, int g, double tolerance,
                      const std::vector<char>* skipped) {
  for (int p = 0; p < mesh.num_points(); ++p)
    if (!(skipped && (*skipped)[p]) &&
        !((u.col(image(mesh, g, p)) - mirrored(g, u.col(p))).cwiseAbs().maxCoeff() <= tolerance))
      return false;
  return true;
}

// The stiffness blocks K(p, q) of the points within the stencil, summed as
// a force model adds them (the same 5 x 5 stencil as StiffnessMatrix).
class StencilBlocks final : public StiffnessSink {
 public:
  explicit StencilBlocks(const Mesh& mesh) : blocks_(static_cast<size_t>(mesh.num_points()) * 25, Eigen::Matrix3d::Zero()) {
    // Each point's mesh row and column, so that add() needs no division.
    for (int p = 0; p < mesh.num_points(); ++p) {
      row_.push_back(mesh.row_of(p));
      col_.push_back(mesh.col_of(p));
    }
  }
  void add(int row_point, int col_point, const Eigen::Matrix3d& block) override {
    const int di = row_[col_point] - row_[row_point], dj = col_[col_point] - col_[row_point];
    if (di >= -2 && di <= 2 && dj >= -2 && dj <= 2) blocks_[slot(row_point, di, dj)] += block;
  }
  const Eigen::Matrix3d& block(int p, int di, int dj) const { return blocks_[slot(p, di, dj)]; }
  double largest() const {
    double out = 0.0;
    for (const auto& b : blocks_) out = std::max(out, b.cwiseAbs().maxCoeff());
    return out;
  }

 private:
  static size_t slot(int p, int di, int dj) { return static_cast<size_t>(p) * 25 + (di + 2) * 5 + (dj + 2); }
  std::vector<int> row_, col_;
  std::vector<Eigen::Matrix3d> blocks_;
};

// Whether element g maps the stiffness onto itself, K(g p, g q) = D_g K(p, q)
// D_g, over the free points, within `tolerance`. Forces alone miss what only
// shows under strain: at the flat rest state the springs carry no tension,
// so a stiffness gradient leaves the forces symmetric but not K.
bool stiffness_maps_onto_itself(const Mesh& mesh, const StencilBlocks& k, const std::vector<char>& fixed, int g,
                                double tolerance) {
  // D_g K D_g flips the sign of entry (r, c) by flip(g, r) flip(g, c).
  const Eigen::Vector3d d(flip(g, 0), flip(g, 1), 1.0);
  const Eigen::Matrix3d signs = d * d.transpose();
  const int nr = mesh.point_rows(), nc = mesh.point_cols();
  // A mirror maps the offset (di, dj) of q from p onto the offset of g q from g p.
  const int si = (g & 2) ? -1 : 1, sj = (g & 1) ? -1 : 1;
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < nc; ++j) {
      const int p = mesh.index(i, j);
      if (fixed[p]) continue;
      const int gp = image(mesh, g, p);
      for (int di = -2; di <= 2; ++di)
        for (int dj = -2; dj <= 2; ++dj) {
          const int qi = i + di, qj = j + dj;
          if (std::abs(di) + std::abs(dj) > 2 || qi < 0 || qj < 0 || qi >= nr || qj >= nc) continue;
          if (fixed[mesh.index(qi, qj)]) continue;
          const Eigen::Matrix3d& here = k.block(p, di, dj);
          const Eigen::Matrix3d& there = k.block(gp, si * di, sj * dj);
          if (!((there - signs.cwiseProduct(here)).cwiseAbs().maxCoeff() <= tolerance)) return false;
        }
    }
  return true;
}

// The largest subgroup whose elements are all in `passing` (bit g set).
MirrorGroup largest_subgroup(unsigned passing) {
  if ((passing & 0b1110u) == 0b1110u) return {0b1111u};
  for (int g = 1; g <= 3; ++g)
    if (passing & (1u << g)) return {1u | (1u << g)};
  return {};
}

}  // namespace

int MirrorGroup::order() const { return has(1) + has(2) + has(3); }

Eigen::Matrix3Xd mirror_projection(const Mesh& mesh, const Eigen::Matrix3Xd& u, MirrorGroup group, unsigned odd,
                                   const std::vector<char>& fixed) {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, mesh.num_points());
  const double count = group.order() + 1;
  for (int p = 0; p < mesh.num_points(); ++p) {
    if (fixed[p]) continue;
    Eigen::Vector3d sum = u.col(p);
    for (int g = 1; g <= 3; ++g)
      if (group.has(g)) sum += character(odd, g) * mirrored(g, u.col(image(mesh, g, p)));
    out.col(p) = sum / count;
  }
  return out;
}

Eigen::Matrix3Xd mirror_average(const Mesh& mesh, const Eigen::Matrix3Xd& x, MirrorGroup group,
                                const std::vector<char>& fixed) {
  const Eigen::Matrix3Xd flat = mesh.rest_positions();
  Eigen::Matrix3Xd out = flat + mirror_projection(mesh, x - flat, group, 0, fixed);
  for (int p = 0; p < mesh.num_points(); ++p)
    if (fixed[p]) out.col(p) = x.col(p);
  return out;
}

std::vector<unsigned> mirror_characters(MirrorGroup group) {
  if (group.trivial()) return {0u};
  if (group.order() == 1) return {0u, group.elements & ~1u};
  return {0u, 0b1010u, 0b1100u, 0b0110u};  // odd in x, odd in y, odd in both mirrors but not their product
}

MirrorClass strongest_mirror_class(const Mesh& mesh, const Eigen::Matrix3Xd& u, MirrorGroup group,
                                   const std::vector<char>& fixed) {
  MirrorClass best{0, -1.0};
  for (unsigned odd : mirror_characters(group))
    if (const double norm = mirror_projection(mesh, u, group, odd, fixed).norm(); norm > best.norm) best = {odd, norm};
  return best;
}

MirrorGroup mirror_symmetry_of(const ForceModel& model, const DeviceState& state, double position_tolerance_m) {
  const Mesh& mesh = model.mesh();
  const std::vector<char> fixed = model.fixed_points(state);
  const Eigen::Matrix3Xd u = state.x - mesh.rest_positions();
  unsigned passing = 0;
  for (int g = 1; g <= 3; ++g)
    if (pattern_symmetric(mesh, state, fixed, g) && maps_onto_itself(mesh, u, g, position_tolerance_m, nullptr))
      passing |= 1u << g;
  MirrorGroup group = largest_subgroup(passing);
  if (group.trivial()) return group;
  // The forces and the stiffness must be mirrored too: effects (a stiffness
  // gradient), jam angles or anything else the state holds can break the
  // symmetry that the positions have.
  DeviceState symmetric = state;
  symmetric.x = mirror_average(mesh, state.x, group, fixed);
  Eigen::Matrix3Xd f;
  model.forces(symmetric, symmetric.x, f);
  double largest = 0.0;
  for (int p = 0; p < mesh.num_points(); ++p)
    if (!fixed[p]) largest = std::max(largest, f.col(p).cwiseAbs().maxCoeff());
  // At an equilibrium the largest force is the residual, the difference of
  // spring forces about k h, which round asymmetrically at 1e-16 of that.
  const double tolerance = 1e-9 * (largest + model.params().spring_k * mesh.spacing());
  unsigned forces_passing = 0;
  for (int g = 1; g <= 3; ++g)
    if (group.has(g) && maps_onto_itself(mesh, f, g, tolerance, &fixed)) forces_passing |= 1u << g;
  if (forces_passing == 0) return {};
  StencilBlocks k(mesh);
  model.add_stiffness(symmetric, symmetric.x, k);
  const double stiffness_tolerance = 1e-9 * k.largest();
  unsigned passing_all = 0;
  for (int g = 1; g <= 3; ++g)
    if ((forces_passing >> g & 1u) && stiffness_maps_onto_itself(mesh, k, fixed, g, stiffness_tolerance))
      passing_all |= 1u << g;
  // A subgroup of the one the positions allow is symmetric about the
  // positions averaged over the larger one as well.
  return largest_subgroup(passing_all);
}

MirrorSubspace::MirrorSubspace(const Mesh& mesh, const StiffnessMatrix& full, MirrorGroup group, unsigned odd)
    : full_(full), num_points_(mesh.num_points()), unknown_of_dof_(full.num_dofs(), -1), sign_of_dof_(full.num_dofs(), 0) {
  auto representative = [&](int p) {
    int rep = p;
    for (int g = 1; g <= 3; ++g)
      if (group.has(g)) rep = std::min(rep, image(mesh, g, p));
    return rep;
  };
  for (int p : full.free_points()) {
    if (representative(p) != p) continue;
    for (int c = 0; c < 3; ++c) {
      // A mirror that fixes the point and flips the component holds it at 0.
      bool free = true;
      for (int g = 1; g <= 3; ++g)
        if (group.has(g) && image(mesh, g, p) == p && character(odd, g) * flip(g, c) < 0) free = false;
      if (!free) continue;
      unknown_of_dof_[full.dof(p, c)] = num_dofs_++;
      sign_of_dof_[full.dof(p, c)] = 1;
    }
  }
  for (int p : full.free_points()) {
    const int rep = representative(p);
    if (rep == p) continue;
    if (full.dof(rep, 0) < 0) throw std::logic_error("MirrorSubspace: the fixed points are not symmetric");
    int g = 1;
    while (!(group.has(g) && image(mesh, g, rep) == p)) ++g;
    for (int c = 0; c < 3; ++c) {
      unknown_of_dof_[full.dof(p, c)] = unknown_of_dof_[full.dof(rep, c)];
      sign_of_dof_[full.dof(p, c)] =
          static_cast<signed char>(character(odd, g) * flip(g, c) * sign_of_dof_[full.dof(rep, c)]);
    }
  }
  weights_ = Eigen::VectorXd::Zero(num_dofs_);
  for (int unknown : unknown_of_dof_)
    if (unknown >= 0) weights_[unknown] += 1.0;

  const Eigen::SparseMatrix<double>& k = full.matrix();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(k.nonZeros());
  for (int col = 0; col < k.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      const int row = unknown_of_dof_[it.row()], column = unknown_of_dof_[col];
      if (row >= 0 && column >= 0) triplets.emplace_back(row, column, 0.0);
    }
  pattern_.resize(num_dofs_, num_dofs_);
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();
  entry_target_.assign(k.nonZeros(), -1);
  entry_sign_.assign(k.nonZeros(), 0);
  for (int col = 0; col < k.outerSize(); ++col)
    for (Eigen::Index e = k.outerIndexPtr()[col]; e < k.outerIndexPtr()[col + 1]; ++e) {
      const int row = unknown_of_dof_[k.innerIndexPtr()[e]], column = unknown_of_dof_[col];
      if (row < 0 || column < 0) continue;
      const int* begin = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[column];
      const int* end = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[column + 1];
      entry_target_[e] = static_cast<int>(std::lower_bound(begin, end, row) - pattern_.innerIndexPtr());
      entry_sign_[e] = static_cast<signed char>(sign_of_dof_[k.innerIndexPtr()[e]] * sign_of_dof_[col]);
    }
}

Eigen::VectorXd MirrorSubspace::gather(const Eigen::Matrix3Xd& field) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(num_dofs_);
  for (int p : full_.free_points())
    for (int c = 0; c < 3; ++c)
      if (const int dof = full_.dof(p, c); unknown_of_dof_[dof] >= 0)
        out[unknown_of_dof_[dof]] += sign_of_dof_[dof] * field(c, p);
  return out;
}

Eigen::Matrix3Xd MirrorSubspace::scatter(const Eigen::VectorXd& dofs) const {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, num_points_);
  for (int p : full_.free_points())
    for (int c = 0; c < 3; ++c)
      if (const int dof = full_.dof(p, c); unknown_of_dof_[dof] >= 0)
        out(c, p) = sign_of_dof_[dof] * dofs[unknown_of_dof_[dof]];
  return out;
}

void MirrorSubspace::reduce(Eigen::SparseMatrix<double>& reduced) const {
  const Eigen::SparseMatrix<double>& k = full_.matrix();
  double* values = reduced.valuePtr();
  std::fill(values, values + reduced.nonZeros(), 0.0);
  const double* full_values = k.valuePtr();
  for (Eigen::Index e = 0; e < k.nonZeros(); ++e)
    if (entry_target_[e] >= 0) values[entry_target_[e]] += entry_sign_[e] * full_values[e];
}

}  // namespace hj
