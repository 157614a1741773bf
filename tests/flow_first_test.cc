// SimulatorOptions::flow_first: where the static solver's fast control does
// not settle, the implicit flow runs before the careful controls. It must
// reach the equilibria the careful controls reach: here the paper's 3 x 4
// array jammed whole just above levelling, then dropped to 0 Pa (the plates
// sag about 32 mm) and raised to 431 Pa (they bulge), as in the demo
// datasets' jammed sweep.
#include <gtest/gtest.h>

#include <cstdio>

#include "model/action.h"
#include "sim/simulator.h"

namespace hj {
namespace {

Simulator jammed_sweep(bool flow_first) {
  const ArrayGeometry geometry{3, 4, 0.038, 4};
  SurfaceParameters params = SurfaceParameters::paper_defaults(geometry);
  params.mass_kg = 0.52;
  params.spring_k = 58.0;
  params.kappa_jam = 7.25;
  SimulatorOptions options;
  options.flow_first = flow_first;
  Simulator sim(geometry, params, options);
  sim.apply(Action::set_pressure(590.0));
  sim.apply(Action::set_pressure(295.0));
  for (int r = 0; r < geometry.rows; ++r)
    for (int c = 0; c < geometry.cols; ++c) sim.apply(Action::jam(r, c));
  return sim;
}

TEST(FlowFirst, ReachesTheEquilibriaOfTheCarefulControls) {
  Simulator flow = jammed_sweep(true), careful = jammed_sweep(false);
  for (double pa : {0.0, 431.25, 862.5}) {
    const SettleReport& a = flow.apply(Action::set_pressure(pa));
    const SettleReport& b = careful.apply(Action::set_pressure(pa));
    std::printf("%.0f Pa: %d steps flow first, %d careful\n", pa, a.iterations, b.iterations);
    ASSERT_TRUE(a.converged) << pa << " Pa";
    ASSERT_TRUE(b.converged) << pa << " Pa";
    EXPECT_LT(a.residual_n, 1e-9);
    const double largest = (flow.state().x - careful.state().x).colwise().norm().maxCoeff();
    EXPECT_LT(largest, 1e-8) << "at " << pa << " Pa the two differ by " << largest * 1000 << " mm";
  }
  // The sweep moved the plates: a real test of the two paths.
  const Mesh& m = flow.mesh();
  const int centre = m.index(m.point_rows() / 2, m.point_cols() / 2);
  EXPECT_GT(flow.state().x(2, centre), 0.010);
}

}  // namespace
}  // namespace hj
