#include "shapes/goal_alignment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "shapes/resample.h"

namespace hj {
namespace {

// Where the minimum of the parabola through (-1, before), (0, at), (1, after)
// lies, in [-0.5, 0.5] when `at` is below both.
double parabola_vertex(double before, double at, double after) {
  const double bend = before - 2.0 * at + after;
  return bend > 0.0 ? std::clamp(0.5 * (before - after) / bend, -0.5, 0.5) : 0.0;
}

// Distance in cells from (x, y) to the nearest place the surface can make a
// sharp valley: an interior node (pinnable) or the clamped boundary.
double distance_to_node_cells(double x, double y, int rows, int cols) {
  double d = std::min({x, cols - x, y, rows - y});
  if (rows > 1 && cols > 1) {
    const double a = std::clamp(std::round(y), 1.0, double(rows - 1));
    const double b = std::clamp(std::round(x), 1.0, double(cols - 1));
    d = std::min(d, std::hypot(x - b, y - a));
  }
  return d;
}

// Throws naming AlignOptions.field unless lo < value <= hi (lo_open) or lo <= value <= hi.
void check_range(double value, double lo, double hi, bool lo_open, const char* field, const char* what) {
  const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
  if (!ok)
    throw std::invalid_argument(std::string("AlignOptions.") + field + " must be " + what + ", got " +
                                std::to_string(value));
}

}  // namespace

void AlignOptions::validate() const {
  check_range(max_shift_cells, 0.0, 0.5, false, "max_shift_cells", "in [0, 0.5] cells");
  check_range(min_scale, 0.0, 1.0, true, "min_scale", "a fraction of the window side in (0, 1]");
  check_range(max_scale, 0.0, 1.0, true, "max_scale", "a fraction of the window side in (0, 1]");
  if (min_scale > max_scale)
    throw std::invalid_argument("AlignOptions.min_scale (" + std::to_string(min_scale) +
                                ") must not exceed AlignOptions.max_scale (" + std::to_string(max_scale) + ")");
  if (shift_steps < 1) throw std::invalid_argument("AlignOptions.shift_steps must be >= 1");
  if (scale_steps < 1) throw std::invalid_argument("AlignOptions.scale_steps must be >= 1");
}

std::vector<GoalValley> goal_valleys(const Eigen::MatrixXd& goal_mm, int segments) {
  const long n_i = goal_mm.rows(), n_j = goal_mm.cols();
  const int rows = int((n_i - 1) / segments), cols = int((n_j - 1) / segments);
  std::vector<GoalValley> out;
  for (long i = 1; i + 1 < n_i; ++i)
    for (long j = 1; j + 1 < n_j; ++j) {
      const double z = goal_mm(i, j);
      double neighbours = 0.0;
      bool lowest = true;
      for (long di = -1; di <= 1; ++di)
        for (long dj = -1; dj <= 1; ++dj) {
          if (di == 0 && dj == 0) continue;
          const double other = goal_mm(i + di, j + dj);
          neighbours += other;
          // Two equal lowest points (a valley halfway between them) count once, at the earlier one.
          const bool earlier = di < 0 || (di == 0 && dj < 0);
          lowest = lowest && (earlier ? z < other : z <= other);
        }
      if (!lowest) continue;
      GoalValley v;
      v.x_cells = (double(j) + parabola_vertex(goal_mm(i, j - 1), z, goal_mm(i, j + 1))) / segments;
      v.y_cells = (double(i) + parabola_vertex(goal_mm(i - 1, j), z, goal_mm(i + 1, j))) / segments;
      v.depth_mm = neighbours / 8.0 - z;
      v.node_distance_cells = distance_to_node_cells(v.x_cells, v.y_cells, rows, cols);
      out.push_back(v);
    }
  return out;
}

double valley_cost(const std::vector<GoalValley>& valleys) {
  double cost = 0.0;
  for (const GoalValley& v : valleys) cost += v.depth_mm * v.node_distance_cells;
  return cost;
}

Region transformed_window(const Region& window, const GoalTransform& t, const ArrayGeometry& geometry) {
  const double width = (window.x1 - window.x0) * t.scale, height = (window.y1 - window.y0) * t.scale;
  // Image rows grow downwards, the array's y upwards.
  const double cx = 0.5 * (window.x0 + window.x1) + t.shift_x_cells * width / geometry.cols;
  const double cy = 0.5 * (window.y0 + window.y1) - t.shift_y_cells * height / geometry.rows;
  Region out;
  out.fractions = false;
  out.x0 = std::round(cx - 0.5 * width) + 0.0;  // + 0.0: no -0 in reports
  out.y0 = std::round(cy - 0.5 * height) + 0.0;
  out.x1 = out.x0 + std::max(1.0, std::round(width));
  out.y1 = out.y0 + std::max(1.0, std::round(height));
  return out;
}

std::vector<AlignmentCandidate> alignment_candidates(const HeightMap& source, const Region& window, const Mesh& mesh,
                                                     double relief_mm, const AlignOptions& options) {
  options.validate();
  const double cols = double(source.z.cols()), rows = double(source.z.rows());
  const auto inside = [&](const Region& w) { return w.x0 >= 0 && w.y0 >= 0 && w.x1 <= cols && w.y1 <= rows; };
  if (window.fractions || !inside(window) || window.x1 <= window.x0 || window.y1 <= window.y0)
    throw std::invalid_argument("alignment window of goal \"" + source.source +
                                "\" must be a non-empty pixel region inside it");

  // The grid, smallest moves first, so a window reached twice keeps its smallest move.
  std::vector<GoalTransform> grid;
  for (int k = 0; k <= options.scale_steps; ++k) {
    const double scale = options.max_scale - (options.max_scale - options.min_scale) * k / options.scale_steps;
    for (int sx = -options.shift_steps; sx <= options.shift_steps; ++sx)
      for (int sy = -options.shift_steps; sy <= options.shift_steps; ++sy)
        grid.push_back({options.max_shift_cells * sx / options.shift_steps,
                        options.max_shift_cells * sy / options.shift_steps, scale});
    if (options.min_scale == options.max_scale) break;
  }
  const auto size_of_move = [](const GoalTransform& t) {
    return std::abs(t.shift_x_cells) + std::abs(t.shift_y_cells) + 4.0 * std::abs(1.0 - t.scale);
  };
  std::stable_sort(grid.begin(), grid.end(),
                   [&](const GoalTransform& a, const GoalTransform& b) { return size_of_move(a) < size_of_move(b); });
  grid.insert(grid.begin(), GoalTransform{});  // the identity, whatever the bounds

  std::vector<AlignmentCandidate> out;
  for (const GoalTransform& t : grid) {
    const Region w = t.is_identity() ? window : transformed_window(window, t, mesh.geometry());
    if (!inside(w)) continue;
    const bool seen = std::any_of(out.begin(), out.end(), [&](const AlignmentCandidate& c) {
      return c.window.x0 == w.x0 && c.window.y0 == w.y0 && c.window.x1 == w.x1 && c.window.y1 == w.y1;
    });
    if (seen) continue;
    const long w_cols = long(w.x1 - w.x0), w_rows = long(w.y1 - w.y0);
    if (source.z.block(long(w.y0), long(w.x0), w_rows, w_cols).array().isNaN().all()) continue;
    const HeightMap part = crop(source, w);
    AlignmentCandidate c{t, w, resample_to_mesh(part, mesh, relief_mm), 0.0, 0};
    const auto valleys = goal_valleys(c.goal_mm, mesh.segments());
    c.valley_cost = valley_cost(valleys);
    c.valleys = int(valleys.size());
    out.push_back(std::move(c));
  }
  std::stable_sort(out.begin() + 1, out.end(), [](const AlignmentCandidate& a, const AlignmentCandidate& b) {
    return a.valley_cost < b.valley_cost;
  });
  return out;
}

}  // namespace hj
