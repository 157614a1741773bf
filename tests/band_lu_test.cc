// The band LU of small step matrices (sim/band_lu.h): it solves what a
// dense LU solves, pivots where the diagonal is zero, says when the matrix
// is singular, keeps the band narrow on a real step matrix, and is chosen
// for the paper's 3 x 4 array but not for a 9 x 12 one.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "model/action.h"
#include "sim/band_lu.h"
#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"

namespace hj {
namespace {

// An unsymmetric matrix with a band of half-width `width` in a scrambled
// order (so the ordering has something to find) and zeros on the
// diagonal of every third row (so the LU must pivot).
Eigen::SparseMatrix<double> scrambled_band(int n, int width, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<int> label(n);
  for (int i = 0; i < n; ++i) label[i] = i;
  std::shuffle(label.begin(), label.end(), rng);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - width); j <= std::min(n - 1, i + width); ++j) {
      if (i == j && i % 3 == 0) continue;
      entries.emplace_back(label[i], label[j], i == j ? 4.0 + value(rng) : value(rng));
    }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

TEST(BandLU, SolvesWhatADenseLUSolves) {
  const Eigen::SparseMatrix<double> a = scrambled_band(120, 7, 1);
  BandLU lu;
  lu.analyze(a);
  EXPECT_LE(lu.half_bandwidth(), 2 * 7 + 2) << "the ordering finds the band back";
  ASSERT_TRUE(lu.factorize(a));
  const Eigen::MatrixXd dense(a);
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
  Eigen::VectorXd dx;
  lu.solve(r, dx);
  const Eigen::VectorXd exact = dense.fullPivLu().solve(r);
  EXPECT_LT((dx - exact).norm(), 1e-10 * exact.norm());
  EXPECT_LT((dense * dx - r).norm(), 1e-12 * r.norm());
  // New values on the same pattern: factorised again, solved again.
  Eigen::SparseMatrix<double> b = a;
  b.coeffs() *= -0.5;
  ASSERT_TRUE(lu.factorize(b));
  lu.solve(r, dx);
  EXPECT_LT((dx + 2.0 * exact).norm(), 1e-10 * exact.norm());
}

TEST(BandLU, SaysWhenTheMatrixIsSingular) {
  Eigen::SparseMatrix<double> a = scrambled_band(30, 3, 2);
  // Row 5 a copy of row 4 (same pattern, a row of zeros is too easy).
  const Eigen::MatrixXd dense(a);
  Eigen::MatrixXd copied = dense;
  copied.row(5) = copied.row(4);
  const Eigen::SparseMatrix<double> singular = copied.sparseView();
  BandLU lu;
  lu.analyze(singular);
  EXPECT_FALSE(lu.factorize(singular));
}

TEST(BandLU, RefusesAnotherPattern) {
  const Eigen::SparseMatrix<double> a = scrambled_band(30, 3, 3);
  BandLU lu;
  lu.analyze(a);
  const Eigen::SparseMatrix<double> other = scrambled_band(30, 4, 3);
  EXPECT_THROW(lu.factorize(other), std::invalid_argument);
  Eigen::SparseMatrix<double> rectangular(30, 31);
  EXPECT_THROW(lu.analyze(rectangular), std::invalid_argument);
}

// The step matrix of a real settle: the paper's 3 x 4 array takes the band
// (its free points form an 11 x 15 grid; a half bandwidth of 50 here, 74
// with every cell jammed, whose bend springs couple points two apart), a
// 9 x 12 array does not.
TEST(BandLU, IsChosenForThePapersArrayNotForALargeOne) {
  for (const ArrayGeometry& geometry : {ArrayGeometry{3, 4, 0.038, 4}, ArrayGeometry{9, 12, 0.038, 4}}) {
    Simulator sim(geometry, SurfaceParameters::paper_defaults(geometry), SimulatorOptions{});
    sim.apply(Action::set_pressure(1000.0));
    sim.apply(Action::jam(1, 1));
    DeviceState state = sim.state();
    StiffnessMatrix k(sim.mesh(), state.fixed_points(sim.mesh()),
                      [&](StiffnessSink& s) { sim.model().add_stiffness(state, state.x, s); });
    // K + mu I at the settled state, as a step of the static solver has it
    // (the constructor only lays out the pattern).
    k.set_zero();
    sim.model().add_stiffness(state, state.x, k);
    for (int p : k.free_points()) k.add(p, p, 0.01 * Eigen::Matrix3d::Identity());
    BandLU lu;
    lu.analyze(k.matrix());
    const bool small = geometry.rows == 3;
    EXPECT_EQ(lu.worthwhile(), small) << geometry.rows << " x " << geometry.cols;
    if (small) {
      EXPECT_LE(lu.half_bandwidth(), 80);
      ASSERT_TRUE(lu.factorize(k.matrix()));
      const Eigen::VectorXd r = Eigen::VectorXd::Ones(k.num_dofs());
      Eigen::VectorXd dx;
      lu.solve(r, dx);
      EXPECT_LT((k.matrix() * dx - r).norm(), 1e-9 * r.norm());
    }
  }
}

}  // namespace
}  // namespace hj
