// Effects written only for tests of diagnose (issue: "Real devices do not
// follow our candidates' exact formulas"): each differs in form from the
// registry's nearest candidate, and the last is like none of them. They are
// registered only in the tools that link this file (synth_offform), never
// in `hapticjam`, so diagnose cannot propose them.
//   test_power_stiffening   t = k s (1 + beta (s/h)^4), where stiffening has (s/h)^2
//   test_interior_contraction  a jammed cell's springs off its border lines
//                           contract (jam_contraction also contracts the border)
//   test_soft_interior      one cell's springs off its border scaled by factor
//                           (cell_defect also scales the border springs)
//   test_camera_bump        a fixed bump the camera sees over cell (row, col),
//                           height_mm high, 8 mm wide (a smudge on its window)
#include <algorithm>
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

// True if spring a-b lies off every cell border line, strictly inside a cell.
bool off_border(const Mesh& mesh, int a, int b) {
  const int p = mesh.segments();
  const int ia = mesh.row_of(a), ja = mesh.col_of(a);
  return mesh.row_of(b) == ia ? ia % p != 0 : ja % p != 0;
}

// The cell (row, col) a spring off the border lines lies in.
std::pair<int, int> cell_of(const Mesh& mesh, int a, int b) {
  const int p = mesh.segments();
  return {std::min(mesh.row_of(a), mesh.row_of(b)) / p, std::min(mesh.col_of(a), mesh.col_of(b)) / p};
}

// A spring effect: extra tension t(s) and its slope, on the springs `selected` picks.
template <class Tension, class Selected>
class SpringEffect final : public Effect {
 public:
  SpringEffect(std::string name, Tension tension, Selected selected, double stiffness_bound)
      : name_(std::move(name)), tension_(tension), selected_(selected), bound_(stiffness_bound) {}
  std::string_view name() const override { return name_; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const double h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      if (!selected_(ctx, a, b)) return;
      add_tension_force(a, b, x, tension_(ctx, (x.col(b) - x.col(a)).norm() - h).first, f);
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const double h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      if (!selected_(ctx, a, b)) return;
      const auto [t, slope] = tension_(ctx, (x.col(b) - x.col(a)).norm() - h);
      add_tension_stiffness(a, b, x, t, slope, sink);
    });
  }

  double point_stiffness_bound(const Mesh&, const SurfaceParameters& params) const override {
    return bound_ * params.spring_k;
  }

 private:
  std::string name_;
  Tension tension_;
  Selected selected_;
  double bound_;
};

template <class Tension, class Selected>
std::unique_ptr<Effect> spring_effect(std::string name, Tension tension, Selected selected, double bound) {
  return std::make_unique<SpringEffect<Tension, Selected>>(std::move(name), tension, selected, bound);
}

const auto kEverySpring = [](const ForceContext&, int, int) { return true; };

HJ_REGISTER_EFFECT(EffectInfo{
    "test_power_stiffening", "test only: t = k s (1 + beta (s/h)^4)", false, {{"beta", "1", 0.0, 0.0, 1e5}},
    [](const EffectParameterValues& v) {
      const double beta = v.at("beta");
      auto tension = [beta](const ForceContext& ctx, double s) {
        const double c = ctx.params.spring_k * beta / std::pow(ctx.mesh.spacing(), 4);
        return std::pair{c * std::pow(s, 5), 5.0 * c * std::pow(s, 4)};
      };
      return spring_effect("test_power_stiffening", tension, kEverySpring, 8.0 * 5.0 * beta * 0.0625);
    }});

HJ_REGISTER_EFFECT(EffectInfo{
    "test_interior_contraction", "test only: a jammed cell's springs off its border lines contract by c",
    false, {{"contraction", "1", 0.0, 0.0, 0.3}},
    [](const EffectParameterValues& v) {
      const double c = v.at("contraction");
      auto tension = [c](const ForceContext& ctx, double) {
        return std::pair{ctx.params.spring_k * c * ctx.mesh.spacing(), 0.0};
      };
      auto selected = [](const ForceContext& ctx, int a, int b) {
        if (!off_border(ctx.mesh, a, b)) return false;
        const auto [r, col] = cell_of(ctx.mesh, a, b);
        return ctx.state.jammed(ctx.mesh, r, col);
      };
      return spring_effect("test_interior_contraction", tension, selected, 0.0);
    }});

HJ_REGISTER_EFFECT(EffectInfo{
    "test_soft_interior", "test only: cell (row, col)'s springs off its border lines have k factor", false,
    {{"factor", "1", 1.0, 0.2, 5.0}, {"row", "cell", 0.0, 0.0, 63.0}, {"col", "cell", 0.0, 0.0, 63.0}},
    [](const EffectParameterValues& v) {
      const double dk_share = v.at("factor") - 1.0;
      const int row = static_cast<int>(std::lround(v.at("row"))), col = static_cast<int>(std::lround(v.at("col")));
      auto tension = [dk_share](const ForceContext& ctx, double s) {
        return std::pair{dk_share * ctx.params.spring_k * s, dk_share * ctx.params.spring_k};
      };
      auto selected = [row, col](const ForceContext& ctx, int a, int b) {
        return off_border(ctx.mesh, a, b) && cell_of(ctx.mesh, a, b) == std::pair{row, col};
      };
      return spring_effect("test_soft_interior", tension, selected, 8.0 * std::max(0.0, dk_share));
    }});

class CameraBump final : public Effect {
 public:
  CameraBump(double height_mm, int row, int col) : height_mm_(height_mm), row_(row), col_(col) {}
  std::string_view name() const override { return "test_camera_bump"; }
  void add_forces(const ForceContext&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&) const override {}
  void add_stiffness(const ForceContext&, const Eigen::Matrix3Xd&, StiffnessSink&) const override {}
  std::optional<double> energy(const ForceContext&, const Eigen::Matrix3Xd&) const override { return 0.0; }

  void adjust_measurement(const Mesh& mesh, const Eigen::VectorXd& x_mm, const Eigen::VectorXd& y_mm,
                          Eigen::MatrixXd& heights_mm) const override {
    const double cell_mm = 1000.0 * mesh.cell_size(), sigma_mm = 8.0;
    const double cx = (col_ + 0.5) * cell_mm, cy = (row_ + 0.5) * cell_mm;
    for (int iy = 0; iy < heights_mm.rows(); ++iy)
      for (int ix = 0; ix < heights_mm.cols(); ++ix) {
        const double r2 = std::pow(x_mm(ix) - cx, 2) + std::pow(y_mm(iy) - cy, 2);
        heights_mm(iy, ix) += height_mm_ * std::exp(-r2 / (2.0 * sigma_mm * sigma_mm));
      }
  }

 private:
  double height_mm_;
  int row_, col_;
};

HJ_REGISTER_EFFECT(EffectInfo{"test_camera_bump",
                              "test only: a bump the camera sees over cell (row, col), 8 mm wide",
                              false,
                              {{"height_mm", "mm", 0.0, 0.0, 50.0},
                               {"row", "cell", 0.0, 0.0, 63.0},
                               {"col", "cell", 0.0, 0.0, 63.0}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<CameraBump>(v.at("height_mm"),
                                                                    static_cast<int>(std::lround(v.at("row"))),
                                                                    static_cast<int>(std::lround(v.at("col"))));
                              },
                              /*measurement_only=*/true});

}  // namespace
}  // namespace hj
