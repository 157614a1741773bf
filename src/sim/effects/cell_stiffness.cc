// Manufacturing variation of the membrane's stiffness as a smooth field over
// the array: each spring's stiffness is k f, with f at the spring's rest
// midpoint (X, Y), scaled to [-1, 1] across the array's width and height,
//   f = 1 + grad_x X + grad_y Y + bulge (1 - X^2)(1 - Y^2).
// A field of three coefficients rather than one factor per cell: the
// registry's parameter list is fixed per effect, whatever the array size,
// and three coefficients stay identifiable from a handful of sessions (a
// factor per cell of a 3 x 4 array would add 12 loosely constrained ones).
// It captures a membrane thicker on one side (gradients) or stretched
// thinner in the middle (bulge < 0). Added to the baseline as the extra
// tension (f - 1) k s, energy (f - 1) k s^2 / 2. All zero is the baseline.
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

class CellStiffness final : public Effect {
 public:
  CellStiffness(double grad_x, double grad_y, double bulge) : grad_x_(grad_x), grad_y_(grad_y), bulge_(bulge) {}
  std::string_view name() const override { return "cell_stiffness"; }

  // f - 1 for the spring a-b.
  double extra_factor(const Mesh& mesh, int a, int b) const {
    const double width = mesh.point_cols() - 1, height = mesh.point_rows() - 1;
    const double mid_j = 0.5 * (mesh.col_of(a) + mesh.col_of(b)), mid_i = 0.5 * (mesh.row_of(a) + mesh.row_of(b));
    const double X = 2.0 * mid_j / width - 1.0, Y = 2.0 * mid_i / height - 1.0;
    return grad_x_ * X + grad_y_ * Y + bulge_ * (1.0 - X * X) * (1.0 - Y * Y);
  }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    if (is_noop()) return;
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      add_tension_force(a, b, x, extra_factor(ctx.mesh, a, b) * k * s, f);
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    if (is_noop()) return;
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double df = extra_factor(ctx.mesh, a, b);
      add_tension_stiffness(a, b, x, df * k * ((x.col(b) - x.col(a)).norm() - h), df * k, sink);
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    double e = 0.0;
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      e += 0.5 * extra_factor(ctx.mesh, a, b) * k * s * s;
    });
    return e;
  }

  double point_stiffness_bound(const Mesh&, const SurfaceParameters& params) const override {
    return 8.0 * params.spring_k * (std::abs(grad_x_) + std::abs(grad_y_) + std::abs(bulge_));
  }

 private:
  bool is_noop() const { return grad_x_ == 0.0 && grad_y_ == 0.0 && bulge_ == 0.0; }
  double grad_x_, grad_y_, bulge_;
};

// Bounds keep f >= 0.1 everywhere.
HJ_REGISTER_EFFECT(EffectInfo{"cell_stiffness",
                              "stiffness varying over the array: k (1 + grad_x X + grad_y Y + bulge (1-X^2)(1-Y^2))",
                              false,
                              {{"grad_x", "1", 0.0, -0.3, 0.3},
                               {"grad_y", "1", 0.0, -0.3, 0.3},
                               {"bulge", "1", 0.0, -0.3, 0.3}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<CellStiffness>(v.at("grad_x"), v.at("grad_y"), v.at("bulge"));
                              }});

}  // namespace
}  // namespace hj
