// A jammed cell contracts (the vacuum compacts the grains): the rest length
// of each of its springs becomes h (1 - c) while it is jammed. A spring on a
// border line between two cells belongs half to each, so its rest length is
// h (1 - c w), w = the jammed share of its cells (0, 1/2 or 1). Added to the
// baseline springs as the constant extra tension k c h w, with energy
// k c h w |d| (up to a constant). c = 0 is the baseline.
#include <algorithm>
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

// The jammed share w of the cells on either side of spring a-b.
double jammed_share(const Mesh& mesh, const DeviceState& state, int a, int b) {
  const int p = mesh.segments();
  const int ia = mesh.row_of(a), ja = mesh.col_of(a), ib = mesh.row_of(b), jb = mesh.col_of(b);
  // Along x: the cell column is fixed, the rows are those just below and
  // above the spring's line (the same row unless it is a border line).
  const bool along_x = ia == ib;
  const int line = along_x ? ia : ja;                          // the spring's row (or column) of points
  const int across = along_x ? std::min(ja, jb) / p : std::min(ia, ib) / p;  // its cell column (or row)
  double w = 0.0;
  for (int side : {line - 1, line}) {
    const int cell_line = static_cast<int>(std::floor((side + 0.5) / p));
    const int r = along_x ? cell_line : across, c = along_x ? across : cell_line;
    if (mesh.valid_cell(r, c) && state.jammed(mesh, r, c)) w += 0.5;
  }
  return w;
}

template <class Fn>
void for_each_contracting_spring(const ForceContext& ctx, Fn&& fn) {
  if (std::none_of(ctx.state.cell_jammed.begin(), ctx.state.cell_jammed.end(), [](char j) { return j != 0; }))
    return;
  for_each_spring(ctx.mesh, [&](int a, int b) {
    const double w = jammed_share(ctx.mesh, ctx.state, a, b);
    if (w > 0.0) fn(a, b, w);
  });
}

class JamContraction final : public Effect {
 public:
  explicit JamContraction(double contraction) : contraction_(contraction) {}
  std::string_view name() const override { return "jam_contraction"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    if (contraction_ == 0.0) return;
    const double t = tension(ctx);
    for_each_contracting_spring(ctx, [&](int a, int b, double w) { add_tension_force(a, b, x, t * w, f); });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    if (contraction_ == 0.0) return;
    const double t = tension(ctx);
    for_each_contracting_spring(ctx, [&](int a, int b, double w) { add_tension_stiffness(a, b, x, t * w, 0.0, sink); });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const double t = tension(ctx);
    double e = 0.0;
    for_each_contracting_spring(ctx, [&](int a, int b, double w) { e += t * w * (x.col(b) - x.col(a)).norm(); });
    return e;
  }

 private:
  // k c h: the extra tension of a fully jammed spring.
  double tension(const ForceContext& ctx) const { return ctx.params.spring_k * contraction_ * ctx.mesh.spacing(); }
  double contraction_;
};

HJ_REGISTER_EFFECT(EffectInfo{"jam_contraction",
                              "a jammed cell contracts: its springs' rest length becomes h (1 - contraction)",
                              false,
                              {{"contraction", "1", 0.0, 0.0, 0.3}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<JamContraction>(v.at("contraction"));
                              }});

}  // namespace
}  // namespace hj
