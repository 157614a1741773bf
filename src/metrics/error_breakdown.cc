#include "metrics/error_breakdown.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace hj {

namespace {

constexpr double kReliefFraction = 0.05;  // a valley's depth and a detail's size, of the goal's relief

void check_heights(const Mesh& mesh, const Eigen::MatrixXd& m, const char* what) {
  if (m.rows() != mesh.point_rows() || m.cols() != mesh.point_cols())
    throw std::invalid_argument(std::string("error_breakdown: ") + what + " is " + std::to_string(m.rows()) + " x " +
                                std::to_string(m.cols()) + ", the mesh has " + std::to_string(mesh.point_rows()) +
                                " x " + std::to_string(mesh.point_cols()) + " points");
  if (!m.allFinite()) throw std::invalid_argument(std::string("error_breakdown: ") + what + " holds non-finite heights");
}

// goal - (a + b predicted), a and b by least squares (b = 0 if predicted is flat).
Eigen::MatrixXd affine_residual(const Eigen::MatrixXd& goal, const Eigen::MatrixXd& predicted) {
  const Eigen::ArrayXXd p = predicted.array() - predicted.mean();
  const Eigen::ArrayXXd g = goal.array() - goal.mean();
  const double pp = (p * p).sum();
  const double b = pp > 0.0 ? (p * g).sum() / pp : 0.0;
  return (g - b * p).matrix();
}

// Distance of point (i, j) from the clamped border, in cells.
double cells_from_border(const Mesh& mesh, int i, int j) {
  const int rows = mesh.point_rows() - 1, cols = mesh.point_cols() - 1;
  return double(std::min({i, j, rows - i, cols - j})) / mesh.segments();
}

// Distance of point (i, j) from the nearest node (cell corner), in cells.
double cells_from_node(const Mesh& mesh, int i, int j) {
  const int p = mesh.segments();
  const int di = std::min(i % p, p - i % p), dj = std::min(j % p, p - j % p);
  return std::hypot(di, dj) / p;
}

// Goal valleys: points no higher than their 8 neighbours and at least
// `depth` below the median of the ring half a cell around them (the median,
// so that a trench through the ring counts, a plateau beside a peak not).
std::vector<std::pair<int, int>> valleys(const Mesh& mesh, const Eigen::MatrixXd& goal, double depth) {
  const int n = mesh.point_rows(), m = mesh.point_cols(), radius = std::max(1, mesh.segments() / 2);
  std::vector<std::pair<int, int>> out;
  std::vector<double> ring;
  for (int i = radius; i + radius < n; ++i)
    for (int j = radius; j + radius < m; ++j) {
      bool lowest = true;
      for (int a = -1; a <= 1 && lowest; ++a)
        for (int b = -1; b <= 1; ++b)
          if (goal(i + a, j + b) < goal(i, j)) lowest = false;
      if (!lowest) continue;
      ring.clear();
      for (int a = -radius; a <= radius; ++a)
        for (int b = -radius; b <= radius; ++b)
          if (std::max(std::abs(a), std::abs(b)) == radius) ring.push_back(goal(i + a, j + b));
      std::nth_element(ring.begin(), ring.begin() + ring.size() / 2, ring.end());
      if (ring[ring.size() / 2] - goal(i, j) >= depth) out.emplace_back(i, j);
    }
  return out;
}

// |goal - its cell's best smooth shape| at each point: bilinear between the
// four corners plus a dome 16 u (1 - u) v (1 - v) fitted by least squares.
Eigen::MatrixXd sub_cell_detail(const Mesh& mesh, const Eigen::MatrixXd& goal) {
  const int p = mesh.segments();
  Eigen::MatrixXd detail = Eigen::MatrixXd::Zero(goal.rows(), goal.cols());
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c) {
      const int i0 = r * p, j0 = c * p;
      const double g00 = goal(i0, j0), g01 = goal(i0, j0 + p), g10 = goal(i0 + p, j0), g11 = goal(i0 + p, j0 + p);
      Eigen::MatrixXd rest(p + 1, p + 1), dome(p + 1, p + 1);
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= p; ++b) {
          const double v = double(a) / p, u = double(b) / p;
          const double bilinear = (1 - v) * ((1 - u) * g00 + u * g01) + v * ((1 - u) * g10 + u * g11);
          rest(a, b) = goal(i0 + a, j0 + b) - bilinear;
          dome(a, b) = 16.0 * u * (1 - u) * v * (1 - v);
        }
      const double amplitude = (rest.array() * dome.array()).sum() / dome.squaredNorm();
      const Eigen::MatrixXd left = (rest - amplitude * dome).cwiseAbs();
      detail.block(i0, j0, p + 1, p + 1) = detail.block(i0, j0, p + 1, p + 1).cwiseMax(left);
    }
  return detail;
}

}  // namespace

std::string ErrorBreakdown::dominant() const {
  const ErrorPlace* best = nullptr;
  for (const ErrorPlace& place : places)
    if (!best || place.error_share - place.area_share > best->error_share - best->area_share) best = &place;
  return best ? best->name : "";
}

ErrorBreakdown error_breakdown(const Mesh& mesh, const Eigen::MatrixXd& goal_mm, const Eigen::MatrixXd& predicted_mm) {
  check_heights(mesh, goal_mm, "the goal");
  check_heights(mesh, predicted_mm, "the predicted surface");
  const double relief = goal_mm.maxCoeff() - goal_mm.minCoeff();
  const Eigen::MatrixXd residual = affine_residual(goal_mm, predicted_mm);
  const Eigen::MatrixXd detail = sub_cell_detail(mesh, goal_mm);
  std::vector<std::pair<int, int>> off_node;
  for (const auto& [i, j] : valleys(mesh, goal_mm, kReliefFraction * relief))
    if (cells_from_node(mesh, i, j) > 0.25) off_node.emplace_back(i, j);

  const auto place_of = [&](int i, int j) {
    if (cells_from_border(mesh, i, j) <= 0.5) return 0;
    for (const auto& [vi, vj] : off_node)
      if (std::hypot(i - vi, j - vj) <= 0.5 * mesh.segments()) return 1;
    if (relief > 0.0 && detail(i, j) > kReliefFraction * relief) return 2;
    return 3;
  };
  ErrorBreakdown out;
  for (const char* name : {"clamped_edge", "valley_between_nodes", "sub_cell_detail", "elsewhere"})
    out.places.push_back({name});
  std::vector<int> count(out.places.size(), 0);
  std::vector<double> squares(out.places.size(), 0.0);
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j) {
      const int k = place_of(i, j);
      ++count[k];
      squares[k] += residual(i, j) * residual(i, j);
    }
  const double total = residual.squaredNorm();
  const int points = mesh.num_points();
  for (std::size_t k = 0; k < out.places.size(); ++k) {
    out.places[k].error_share = total > 0.0 ? squares[k] / total : 0.0;
    out.places[k].area_share = double(count[k]) / points;
    out.places[k].rms_mm = count[k] ? std::sqrt(squares[k] / count[k]) : 0.0;
  }
  out.rms_mm = std::sqrt(total / points);
  return out;
}

}  // namespace hj
