// The stability check every converged settle makes (sim/divergence_mode.h)
// on a jammed and pinned 9 x 12 state, and its LDL^T of sym(K) alone in
// SuiteSparse AMD's order (the check's) and, for the ratio, in the mesh's
// band order.
// Run: ./build/hj_bench --benchmark_filter=StabilityCheck
#include <benchmark/benchmark.h>

#include <Eigen/SparseCholesky>

#include "sim/amd_ordering.h"
#include "sim/divergence_mode.h"
#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"

namespace {

// A 9 x 12 dome with its centre cell jammed and a node of it pinned at
// 2 kPa, then at 1.9 kPa: an equilibrium whose K the check factors.
Eigen::SparseMatrix<double> jammed_stiffness() {
  const hj::ArrayGeometry g{9, 12, 0.038, 4};
  hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g));
  sim.apply(hj::Action::set_pressure(2000.0));
  sim.apply(hj::Action::jam(4, 6));
  sim.apply(hj::Action::pin(4, 6));
  sim.apply(hj::Action::set_pressure(1900.0));
  const hj::ForceModel& model = sim.model();
  const hj::DeviceState& state = sim.state();
  hj::StiffnessMatrix k(model.mesh(), model.fixed_points(state),
                        [&](hj::StiffnessSink& sink) { model.add_stiffness(state, state.x, sink); });
  k.set_zero();  // the constructor lays out the pattern; this fills it
  model.add_stiffness(state, state.x, k);
  return k.matrix();
}

void BM_StabilityCheck(benchmark::State& state) {
  const Eigen::SparseMatrix<double> k = jammed_stiffness();
  // The whole search: the LDL^T, then, since sym(K) is not positive definite
  // here, K's LU and inverse iteration for its eigenvalue nearest zero.
  for (auto _ : state) benchmark::DoNotOptimize(hj::divergence_mode(k));
}

// The LDL^T alone, in AMD's order (the check's) or the mesh's band order.
template <typename Ordering>
void BM_StabilityLdlt(benchmark::State& state) {
  const Eigen::SparseMatrix<double> k = jammed_stiffness();
  const Eigen::SparseMatrix<double> sym = 0.5 * (k + Eigen::SparseMatrix<double>(k.transpose()));
  long fill = 0;
  for (auto _ : state) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Ordering> ldlt(sym);
    if (ldlt.info() != Eigen::Success) state.SkipWithError("the LDL^T broke down");
    fill = ldlt.matrixL().nestedExpression().nonZeros();
  }
  state.counters["L_entries"] = static_cast<double>(fill);
  state.counters["unknowns"] = static_cast<double>(k.rows());
}

}  // namespace

BENCHMARK(BM_StabilityCheck)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StabilityLdlt<hj::SuiteSparseAmdOrdering>)->Name("BM_StabilityCheckLdlt/amd")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StabilityLdlt<Eigen::NaturalOrdering<int>>)->Name("BM_StabilityCheckLdlt/band")->Unit(benchmark::kMillisecond);
