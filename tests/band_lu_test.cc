// The band LU of small step matrices (sim/band_lu.h): it solves what a
// dense LU solves, rounds as LAPACK's one-pivot-at-a-time elimination,
// pivots where the diagonal is zero, says when the matrix
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

// LAPACK's dgbtf2 / dgbtrs on the dense matrix in the band's order: one
// pivot at a time, row swaps from the pivot's column rightwards, a zero
// factor skipped. Outside the band it only subtracts zeros.
Eigen::VectorXd one_pivot_at_a_time(const Eigen::SparseMatrix<double>& a, const BandLU& lu, const Eigen::VectorXd& r) {
  const int n = static_cast<int>(a.rows());
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  for (int col = 0; col < n; ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      m(lu.ordered_index(static_cast<int>(it.row())), lu.ordered_index(col)) = it.value();
  std::vector<int> pivots(n);
  for (int j = 0; j < n; ++j) {
    int p = j;
    for (int i = j + 1; i < n; ++i)
      if (std::abs(m(i, j)) > std::abs(m(p, j))) p = i;
    pivots[j] = p;
    for (int c = j; c < n; ++c) std::swap(m(j, c), m(p, c));
    const double inverse = 1.0 / m(j, j);
    for (int i = j + 1; i < n; ++i) m(i, j) *= inverse;
    for (int c = j + 1; c < n; ++c)
      if (m(j, c) != 0.0)
        for (int i = j + 1; i < n; ++i) m(i, c) -= m(i, j) * m(j, c);
  }
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[lu.ordered_index(i)] = r[i];
  for (int j = 0; j < n; ++j) {
    std::swap(b[j], b[pivots[j]]);
    for (int i = j + 1; i < n; ++i) b[i] -= m(i, j) * b[j];
  }
  for (int j = n - 1; j >= 0; --j) {
    b[j] /= m(j, j);
    for (int i = j - 1; i >= 0; --i) b[i] -= m(i, j) * b[j];
  }
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = b[lu.ordered_index(i)];
  return x;
}

// Each element sees dgbtf2's subtractions in dgbtf2's order, whatever the
// kernel's vector width or blocking, so that a settle's digits are the same
// on every machine. Bands from 1 to 12 wide, with row swaps and without.
TEST(BandLU, RoundsExactlyAsOnePivotAtATime) {
  for (unsigned seed = 0; seed < 24; ++seed) {
    const int n = 9 + 13 * static_cast<int>(seed % 7), width = 1 + static_cast<int>(seed % 12);
    Eigen::SparseMatrix<double> a = scrambled_band(n, width, 100 + seed);
    if (seed % 2 == 1) {  // a heavy diagonal: no row swaps
      Eigen::SparseMatrix<double> diagonal(n, n);
      diagonal.setIdentity();
      a += 8.0 * diagonal;
    }
    BandLU lu;
    lu.analyze(a);
    ASSERT_TRUE(lu.factorize(a)) << "seed " << seed;
    const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    Eigen::VectorXd dx;
    lu.solve(r, dx);
    const Eigen::VectorXd expected = one_pivot_at_a_time(a, lu, r);
    for (int i = 0; i < n; ++i) ASSERT_EQ(dx[i], expected[i]) << "seed " << seed << ", n " << n << ", width " << width << ", row " << i;
  }
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
