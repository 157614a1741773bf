#include "sim/band_lu.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace hj {

namespace {

using Graph = std::vector<std::vector<int>>;

// Breadth-first levels from `root` over the unvisited part of its
// component; returns the nodes in visiting order, neighbours by rising
// degree (Cuthill-McKee), and the number of levels.
std::vector<int> breadth_first(const Graph& graph, int root, std::vector<int>& level, int& depth) {
  std::vector<int> order = {root};
  std::fill(level.begin(), level.end(), -1);
  level[root] = 0;
  std::vector<int> next;
  for (size_t head = 0; head < order.size(); ++head) {
    const int node = order[head];
    next.clear();
    for (int other : graph[node])
      if (level[other] < 0) {
        level[other] = level[node] + 1;
        next.push_back(other);
      }
    std::sort(next.begin(), next.end(),
              [&](int a, int b) { return graph[a].size() != graph[b].size() ? graph[a].size() < graph[b].size() : a < b; });
    order.insert(order.end(), next.begin(), next.end());
  }
  depth = level[order.back()] + 1;
  return order;
}

// Reverse Cuthill-McKee, each component from a pseudo-peripheral node
// (George and Liu: restart from a lowest-degree node of the last level
// while that deepens the level structure).
std::vector<int> reverse_cuthill_mckee(const Graph& graph) {
  const int n = static_cast<int>(graph.size());
  std::vector<int> result, level(n, -1);
  std::vector<char> placed(n, 0);
  result.reserve(n);
  for (int seed = 0; seed < n; ++seed) {
    if (placed[seed]) continue;
    int root = seed, depth = 0;
    std::vector<int> order = breadth_first(graph, root, level, depth);
    for (int round = 0; round < 8; ++round) {
      int candidate = order.back();
      for (int node : order)
        if (level[node] == depth - 1 && graph[node].size() < graph[candidate].size()) candidate = node;
      int candidate_depth = 0;
      std::vector<int> candidate_order = breadth_first(graph, candidate, level, candidate_depth);
      if (candidate_depth <= depth) break;
      root = candidate;
      depth = candidate_depth;
      order = std::move(candidate_order);
    }
    for (int node : order) placed[node] = 1;
    result.insert(result.end(), order.rbegin(), order.rend());
  }
  return result;
}

// 4 n b^2 (a band LU's flops, b the half bandwidth) above which UMFPACK is
// as fast: the band LU wins at 3 x 4, p = 6 (3.0e7) and loses from
// 3 x 4, p = 10 (2.2e8) and 9 x 12, p = 4 (2.8e8).
constexpr double kMaxBandFlops = 4e7;

// idamax: the offset of the first of column[0 .. below] of largest
// magnitude (a NaN never wins; 0 if column[0] is one). A running maximum
// without branches (a > b ? a : b is maxsd's own rule), then a scan for the
// first entry that equals it, which is nearly always the diagonal: cheaper
// than comparing each entry with the pivot so far, reloaded by its index.
__attribute__((always_inline)) inline int first_largest(const double* column, int below) {
  double largest = std::abs(column[0]);
  for (int r = 1; r <= below; ++r) {
    const double m = std::abs(column[r]);
    largest = m > largest ? m : largest;
  }
  for (int r = 0; r <= below; ++r)
    if (std::abs(column[r]) == largest) return r;
  return 0;
}

}  // namespace

void BandLU::analyze(const Eigen::SparseMatrix<double>& a) {
  if (a.rows() != a.cols()) throw std::invalid_argument("BandLU: the matrix is not square");
  n_ = static_cast<int>(a.rows());
  Graph graph(n_);
  for (int col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      if (it.row() != col) {
        graph[it.row()].push_back(col);
        graph[col].push_back(static_cast<int>(it.row()));
      }
  for (auto& neighbours : graph) {
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  }
  const std::vector<int> order = reverse_cuthill_mckee(graph);
  new_of_.assign(n_, 0);
  for (int i = 0; i < n_; ++i) new_of_[order[i]] = i;
  bandwidth_ = 0;
  for (int col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      bandwidth_ = std::max(bandwidth_, std::abs(new_of_[it.row()] - new_of_[col]));
  ldab_ = 3 * bandwidth_ + 1;
  position_.clear();
  position_.reserve(a.nonZeros());
  for (int col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it) {
      const int i = new_of_[it.row()], j = new_of_[col];
      position_.push_back(j * ldab_ + 2 * bandwidth_ + i - j);  // AB(kl + ku + i - j, j)
    }
  band_.assign(static_cast<size_t>(ldab_) * n_, 0.0);
  pivots_.assign(n_, 0);
  work_.resize(n_);
}

bool BandLU::worthwhile() const {
  const double b = bandwidth_;
  return 4.0 * n_ * b * b <= kMaxBandFlops;
}

// The elimination's updates are most of a jammed settle's time: a clone for
// AVX2 (picked at load time) runs them twice as wide. AVX2 brings no FMA, so
// each element rounds as in the default clone and the results are the same.
// Blocking the pivots in panels does not pay at these bands: the columns
// sit in L1, and the bookkeeping per column costs more than the loads saved.
#define HJ_BAND_KERNEL __attribute__((target_clones("avx2", "default")))

HJ_BAND_KERNEL bool BandLU::factorize(const Eigen::SparseMatrix<double>& a) {
  if (a.rows() != n_ || a.nonZeros() != static_cast<Eigen::Index>(position_.size()))
    throw std::invalid_argument("BandLU: the matrix is not the analysed pattern");
  std::fill(band_.begin(), band_.end(), 0.0);
  size_t k = 0;
  for (int col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it) band_[position_[k++]] = it.value();
  // LAPACK's dgbtf2, unblocked, 0-based: A(i, j) is band_[j * ldab + kv + i - j].
  const int kl = bandwidth_, kv = 2 * bandwidth_, ld = ldab_;
  double* ab = band_.data();
  bool singular = false;
  int ju = 0;  // the last column the elimination so far has reached
  for (int j = 0; j < n_; ++j) {
    double* column = ab + static_cast<size_t>(j) * ld + kv;  // A(j, j) onwards
    const int below = std::min(kl, n_ - 1 - j);
    const int pivot = first_largest(column, below);
    pivots_[j] = j + pivot;
    if (column[pivot] == 0.0) {
      singular = true;
      continue;
    }
    ju = std::max(ju, std::min(j + bandwidth_ + pivot, n_ - 1));  // ku = kl
    if (pivot != 0)  // rows j and j + pivot over columns j .. ju: stride ld - 1 in the band
      for (int c = j; c <= ju; ++c) std::swap(column[(c - j) * (ld - 1)], column[(c - j) * (ld - 1) + pivot]);
    const double inverse = 1.0 / column[0];
    for (int r = 1; r <= below; ++r) column[r] *= inverse;
    for (int c = j + 1; c <= ju; ++c) {
      double* target = column + (c - j) * (ld - 1);  // A(j, c): then A(j + r, c) at target[r]
      const double factor = target[0];
      if (factor != 0.0)
        for (int r = 1; r <= below; ++r) target[r] -= column[r] * factor;
    }
  }
  return !singular;
}

HJ_BAND_KERNEL void BandLU::solve(const Eigen::VectorXd& r, Eigen::VectorXd& dx) const {
  const int kl = bandwidth_, kv = 2 * bandwidth_, ld = ldab_;
  const double* ab = band_.data();
  double* b = work_.data();
  for (int i = 0; i < n_; ++i) b[new_of_[i]] = r[i];
  for (int j = 0; j < n_; ++j) {  // L, with the row swaps
    const int below = std::min(kl, n_ - 1 - j);
    if (pivots_[j] != j) std::swap(b[j], b[pivots_[j]]);
    const double* column = ab + static_cast<size_t>(j) * ld + kv;
    for (int r = 1; r <= below; ++r) b[j + r] -= column[r] * b[j];
  }
  for (int j = n_ - 1; j >= 0; --j) {  // U: kv superdiagonals
    const double* column = ab + static_cast<size_t>(j) * ld + kv;
    b[j] /= column[0];
    const int above = std::min(kv, j);
    for (int r = 1; r <= above; ++r) b[j - r] -= column[-r] * b[j];
  }
  dx.resize(n_);
  for (int i = 0; i < n_; ++i) dx[i] = b[new_of_[i]];
}

}  // namespace hj
