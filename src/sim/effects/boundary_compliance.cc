// The clamped edge gives a little: with this effect the boundary points are
// free (Effect::frees_boundary) and each is tied to its rest position by an
// isotropic spring k_edge,
//   F = -k_edge (x - x_rest),   E = 1/2 k_edge |x - x_rest|^2,
// and the structural springs along the edge, which the baseline leaves out
// because both their ends are fixed there, pull on them (k, rest length h).
// The baseline is the limit k_edge -> infinity; the bound 1e6 N/m moves the
// edge by about a micrometre.
#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

// Calls fn(a, b) for every spring with both ends on the clamped edge.
template <class Fn>
void for_each_edge_spring(const Mesh& mesh, Fn&& fn) {
  const int nr = mesh.point_rows(), nc = mesh.point_cols();
  for (int j = 0; j + 1 < nc; ++j) {
    fn(mesh.index(0, j), mesh.index(0, j + 1));
    fn(mesh.index(nr - 1, j), mesh.index(nr - 1, j + 1));
  }
  for (int i = 0; i + 1 < nr; ++i) {
    fn(mesh.index(i, 0), mesh.index(i + 1, 0));
    fn(mesh.index(i, nc - 1), mesh.index(i + 1, nc - 1));
  }
}

class BoundaryCompliance final : public Effect {
 public:
  explicit BoundaryCompliance(double k_edge) : k_edge_(k_edge) {}
  std::string_view name() const override { return "boundary_compliance"; }
  bool frees_boundary() const override { return true; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const Mesh& mesh = ctx.mesh;
    const double k = ctx.params.spring_k, h = mesh.spacing();
    for (int p = 0; p < mesh.num_points(); ++p)
      if (mesh.is_boundary(p)) f.col(p) -= k_edge_ * (x.col(p) - rest(mesh, p));
    for_each_edge_spring(mesh, [&](int a, int b) { add_tension_force(a, b, x, k * ((x.col(b) - x.col(a)).norm() - h), f); });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const Mesh& mesh = ctx.mesh;
    const double k = ctx.params.spring_k, h = mesh.spacing();
    const Eigen::Matrix3d tether = k_edge_ * Eigen::Matrix3d::Identity();
    for (int p = 0; p < mesh.num_points(); ++p)
      if (mesh.is_boundary(p)) sink.add(p, p, tether);
    for_each_edge_spring(mesh, [&](int a, int b) {
      add_tension_stiffness(a, b, x, k * ((x.col(b) - x.col(a)).norm() - h), k, sink);
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const Mesh& mesh = ctx.mesh;
    const double k = ctx.params.spring_k, h = mesh.spacing();
    double e = 0.0;
    for (int p = 0; p < mesh.num_points(); ++p)
      if (mesh.is_boundary(p)) e += 0.5 * k_edge_ * (x.col(p) - rest(mesh, p)).squaredNorm();
    for_each_edge_spring(mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      e += 0.5 * k * s * s;
    });
    return e;
  }

  double point_stiffness_bound(const Mesh&, const SurfaceParameters&) const override { return k_edge_; }

 private:
  static Eigen::Vector3d rest(const Mesh& mesh, int p) {
    return {mesh.col_of(p) * mesh.spacing(), mesh.row_of(p) * mesh.spacing(), 0.0};
  }
  double k_edge_;
};

HJ_REGISTER_EFFECT(EffectInfo{"boundary_compliance",
                              "the clamped edge gives: edge points tied to their rest positions by springs k_edge",
                              false,
                              {{"k_edge", "N/m", 1000.0, 10.0, 1e6}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<BoundaryCompliance>(v.at("k_edge"));
                              }});

}  // namespace
}  // namespace hj
