// A manufacturing defect of one cell: the springs of cell (row, col) have
// stiffness k factor instead of k (factor < 1 a soft cell, > 1 a stiff one).
// A spring is the cell's if its rest midpoint lies in the closed cell, so
// the springs on the cell's border, shared with its neighbours, are scaled
// too. Added to the baseline as the extra tension (factor - 1) k s, energy
// (factor - 1) k s^2 / 2. factor 1 is the baseline. row and col name the
// cell; their unit "cell" keeps fits from moving them (calib/fit_parameters.h):
// diagnose searches the cells (calib/cell_search.h). A cell outside the
// array changes nothing.
#include <algorithm>
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

class CellDefect final : public Effect {
 public:
  CellDefect(double factor, int row, int col) : factor_(factor), row_(row), col_(col) {}
  std::string_view name() const override { return "cell_defect"; }

  // True if the spring a-b belongs to the defective cell.
  bool in_cell(const Mesh& mesh, int a, int b) const {
    const int p = mesh.segments();
    const double mid_i = 0.5 * (mesh.row_of(a) + mesh.row_of(b)), mid_j = 0.5 * (mesh.col_of(a) + mesh.col_of(b));
    return mid_i >= row_ * p && mid_i <= (row_ + 1) * p && mid_j >= col_ * p && mid_j <= (col_ + 1) * p;
  }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    if (factor_ == 1.0) return;
    const double dk = (factor_ - 1.0) * ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      if (in_cell(ctx.mesh, a, b)) add_tension_force(a, b, x, dk * ((x.col(b) - x.col(a)).norm() - h), f);
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    if (factor_ == 1.0) return;
    const double dk = (factor_ - 1.0) * ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      if (in_cell(ctx.mesh, a, b)) add_tension_stiffness(a, b, x, dk * ((x.col(b) - x.col(a)).norm() - h), dk, sink);
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const double dk = (factor_ - 1.0) * ctx.params.spring_k, h = ctx.mesh.spacing();
    double e = 0.0;
    for_each_spring(ctx.mesh, [&](int a, int b) {
      if (!in_cell(ctx.mesh, a, b)) return;
      const double s = (x.col(b) - x.col(a)).norm() - h;
      e += 0.5 * dk * s * s;
    });
    return e;
  }

  double point_stiffness_bound(const Mesh&, const SurfaceParameters& params) const override {
    return 8.0 * params.spring_k * std::max(0.0, factor_ - 1.0);
  }

 private:
  double factor_;
  int row_, col_;
};

HJ_REGISTER_EFFECT(EffectInfo{"cell_defect",
                              "one cell's springs k factor (a soft or stiff cell); row, col name the cell",
                              false,
                              {{"factor", "1", 1.0, 0.2, 5.0},
                               {"row", "cell", 0.0, 0.0, 63.0},
                               {"col", "cell", 0.0, 0.0, 63.0}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<CellDefect>(v.at("factor"),
                                                                    static_cast<int>(std::lround(v.at("row"))),
                                                                    static_cast<int>(std::lround(v.at("col"))));
                              }});

}  // namespace
}  // namespace hj
