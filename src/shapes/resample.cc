#include "shapes/resample.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace hj {
namespace {

struct Overlap {
  long pixel;     // index along the axis, from the axis' origin
  double length;  // of the footprint inside this pixel, in pixels
};

// Along one axis of n_pixels (pixel q covers [q, q+1]): the footprints of
// n_points points spread evenly from 0 to n_pixels, each [t - h/2, t + h/2]
// clipped to [0, n_pixels], as lists of overlapped pixels.
std::vector<std::vector<Overlap>> footprints(int n_points, long n_pixels) {
  const double h = double(n_pixels) / (n_points - 1);
  std::vector<std::vector<Overlap>> out(n_points);
  for (int k = 0; k < n_points; ++k) {
    const double lo = std::max(0.0, (k - 0.5) * h), hi = std::min(double(n_pixels), (k + 0.5) * h);
    for (long q = long(std::floor(lo)); q < n_pixels && double(q) < hi; ++q) {
      const double len = std::min(hi, double(q + 1)) - std::max(lo, double(q));
      if (len > 0.0) out[k].push_back({q, len});
    }
  }
  return out;
}

void check_goal(const HeightMap& goal, double max_height_mm) {
  const std::string name = "goal \"" + goal.source + "\"";
  if (!std::isfinite(max_height_mm) || max_height_mm <= 0.0)
    throw std::invalid_argument("max_height_mm must be a positive height in mm, got " + std::to_string(max_height_mm));
  if (goal.z.size() == 0) throw std::invalid_argument(name + " is empty");
  if (goal.z.array().isNaN().all()) throw std::invalid_argument(name + " has no valid (non-NaN) height");
  if (goal.z.array().isInf().any()) throw std::invalid_argument(name + " has an infinite height");
  if (goal.uncovered_height && !std::isfinite(*goal.uncovered_height))
    throw std::invalid_argument(name + " has a non-finite uncovered_height");
}

// For points whose footprint had no valid pixel (weight 0): the value of the
// valid pixel nearest to the point, by OpenCV's labelled distance transform.
void fill_from_nearest(const Eigen::MatrixXd& z, const Eigen::MatrixXd& weight, Eigen::MatrixXd& value) {
  const long rows = z.rows(), cols = z.cols();
  cv::Mat no_data(int(rows), int(cols), CV_8U), distance, labels;
  for (long r = 0; r < rows; ++r)
    for (long c = 0; c < cols; ++c) no_data.at<unsigned char>(int(r), int(c)) = std::isnan(z(r, c)) ? 1 : 0;
  cv::distanceTransform(no_data, distance, labels, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);
  // Each valid pixel has its own label; every pixel carries its nearest one's.
  std::vector<double> value_of_label(std::size_t(rows * cols) + 1, 0.0);
  for (long r = 0; r < rows; ++r)
    for (long c = 0; c < cols; ++c)
      if (!std::isnan(z(r, c))) value_of_label[std::size_t(labels.at<int>(int(r), int(c)))] = z(r, c);
  const double dy = double(rows) / double(value.rows() - 1), dx = double(cols) / double(value.cols() - 1);
  for (long i = 0; i < value.rows(); ++i) {
    for (long j = 0; j < value.cols(); ++j) {
      if (weight(i, j) > 0.0) continue;
      // The pixel under the point; image rows count from the top.
      const long c = std::clamp(long(std::floor(double(j) * dx)), 0L, cols - 1);
      const long r = std::clamp(rows - 1 - long(std::floor(double(i) * dy)), 0L, rows - 1);
      value(i, j) = value_of_label[std::size_t(labels.at<int>(int(r), int(c)))];
    }
  }
}

// The goal's area-weighted mean over each point's footprint, in its own units.
Eigen::MatrixXd average_to_mesh(const HeightMap& goal, const Mesh& mesh) {
  // (rows x cols), row 0 = top; NaN that means "floor" becomes that height.
  const Eigen::MatrixXd z = goal.uncovered_height
                                ? Eigen::MatrixXd(goal.z.array().isNaN().select(*goal.uncovered_height, goal.z.array()))
                                : goal.z;
  const long rows = z.rows(), cols = z.cols();
  const int n_i = mesh.point_rows(), n_j = mesh.point_cols();
  const auto along_x = footprints(n_j, cols);
  const auto along_y = footprints(n_i, rows);  // pixel index counted from the bottom row

  // Along x: per image row and mesh column, weighted sums of valid values and of weights.
  Eigen::MatrixXd sum_x = Eigen::MatrixXd::Zero(rows, n_j), weight_x = Eigen::MatrixXd::Zero(rows, n_j);
  for (int j = 0; j < n_j; ++j) {
    for (const Overlap& o : along_x[j]) {
      for (long r = 0; r < rows; ++r) {
        const double v = z(r, o.pixel);
        if (std::isnan(v)) continue;
        sum_x(r, j) += o.length * v;
        weight_x(r, j) += o.length;
      }
    }
  }
  // Along y, flipping the image rows: mesh row i = 0 is the image's bottom.
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n_i, n_j), weight = Eigen::MatrixXd::Zero(n_i, n_j);
  for (int i = 0; i < n_i; ++i) {
    for (const Overlap& o : along_y[i]) {
      const long r = rows - 1 - o.pixel;
      sum.row(i) += o.length * sum_x.row(r);
      weight.row(i) += o.length * weight_x.row(r);
    }
  }
  Eigen::MatrixXd value = (weight.array() > 0.0).select(sum.array() / weight.array(), 0.0);
  if ((weight.array() <= 0.0).any()) fill_from_nearest(z, weight, value);
  return value;
}

}  // namespace

double default_relief_mm(const ArrayGeometry& geometry) {
  return kReliefPerShortSide * std::min(geometry.rows, geometry.cols) * geometry.cell_size_m * 1000.0;
}

double relief_or_default_mm(double requested_mm, const ArrayGeometry& geometry) {
  return requested_mm > 0.0 ? requested_mm : default_relief_mm(geometry);
}

Eigen::MatrixXd resample_to_mesh(const HeightMap& goal, const Mesh& mesh, double max_height_mm) {
  check_goal(goal, max_height_mm);
  const Eigen::MatrixXd value = average_to_mesh(goal, mesh);
  const int n_i = mesh.point_rows(), n_j = mesh.point_cols();
  // Lowest point 0, highest max_height_mm.
  const double lo = value.minCoeff(), hi = value.maxCoeff();
  if (hi - lo <= 1e-12 * std::max({1.0, std::abs(lo), std::abs(hi)})) return Eigen::MatrixXd::Zero(n_i, n_j);
  return (value.array() - lo) * (max_height_mm / (hi - lo));
}

Eigen::MatrixXd resample_to_mesh(const HeightMap& goal, const Mesh& mesh) {
  return resample_to_mesh(goal, mesh, default_relief_mm(mesh.geometry()));
}

GoalHeights parse_goal_heights(const std::string& name) {
  if (name == "scaled") return GoalHeights::kScaled;
  if (name == "absolute") return GoalHeights::kAbsolute;
  throw std::invalid_argument("unknown goal heights \"" + name + "\"; known: scaled (stretched to the relief), absolute (mm)");
}

void check_absolute_goal_format(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".csv" && ext != ".tif" && ext != ".tiff")
    throw std::invalid_argument("goal \"" + file.string() + "\": absolute heights (mm) need a CSV or float TIFF " +
                                "height goal, not \"" + ext + "\" (its values are not millimetres)");
}

Eigen::MatrixXd absolute_to_mesh(const HeightMap& goal, const Mesh& mesh) {
  check_goal(goal, 1.0);
  const int n_i = mesh.point_rows(), n_j = mesh.point_cols();
  if (goal.z.rows() != n_i || goal.z.cols() != n_j) return average_to_mesh(goal, mesh);
  // One value per mesh point; the image's top row is the mesh's last.
  Eigen::MatrixXd value(n_i, n_j);
  for (int i = 0; i < n_i; ++i)
    for (int j = 0; j < n_j; ++j) {
      const long r = n_i - 1 - i;
      const double v = goal.uncovered_height && std::isnan(goal.z(r, j)) ? *goal.uncovered_height : goal.z(r, j);
      if (std::isnan(v))
        throw std::invalid_argument("goal \"" + goal.source + "\" at the mesh points (absolute heights): row " +
                                    std::to_string(r) + ", column " + std::to_string(j) + " is NaN");
      value(i, j) = v;
    }
  return value;
}

Eigen::MatrixXd goal_to_mesh(const HeightMap& goal, const Mesh& mesh, GoalHeights heights, double max_height_mm) {
  if (heights == GoalHeights::kAbsolute) return absolute_to_mesh(goal, mesh);
  return resample_to_mesh(goal, mesh, relief_or_default_mm(max_height_mm, mesh.geometry()));
}

}  // namespace hj
