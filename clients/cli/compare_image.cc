#include "compare_image.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace hj::cli {

namespace {

constexpr int kPixelsPerCell = 96;

// One panel: heights mapped from [lo, hi] to a colour map, mesh row i drawn
// with +y up (row 0 at the bottom), cell borders in white.
cv::Mat panel(const Mesh& mesh, const Eigen::MatrixXd& z, double lo, double hi, int colormap) {
  cv::Mat grey(z.rows(), z.cols(), CV_8UC1);
  for (int i = 0; i < z.rows(); ++i)
    for (int j = 0; j < z.cols(); ++j)
      grey.at<uchar>(static_cast<int>(z.rows()) - 1 - i, j) =
          cv::saturate_cast<uchar>(255.0 * (z(i, j) - lo) / std::max(hi - lo, 1e-9));
  cv::Mat big, colour;
  cv::resize(grey, big, cv::Size(mesh.cols() * kPixelsPerCell, mesh.rows() * kPixelsPerCell), 0, 0, cv::INTER_CUBIC);
  cv::applyColorMap(big, colour, colormap);
  for (int c = 0; c <= mesh.cols(); ++c)
    cv::line(colour, {c * kPixelsPerCell, 0}, {c * kPixelsPerCell, colour.rows}, cv::Scalar(255, 255, 255), 1);
  for (int r = 0; r <= mesh.rows(); ++r)
    cv::line(colour, {0, r * kPixelsPerCell}, {colour.cols, r * kPixelsPerCell}, cv::Scalar(255, 255, 255), 1);
  return colour;
}

cv::Mat titled(const cv::Mat& image, const std::string& title) {
  cv::Mat out(image.rows + 28, image.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  image.copyTo(out(cv::Rect(0, 28, image.cols, image.rows)));
  cv::putText(out, title, {6, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

}  // namespace

void write_compare_png(const std::filesystem::path& path, const Mesh& mesh, const Eigen::MatrixXd& goal_mm,
                       const Eigen::MatrixXd& predicted_mm) {
  const double lo = std::min(goal_mm.minCoeff(), predicted_mm.minCoeff());
  const double hi = std::max(goal_mm.maxCoeff(), predicted_mm.maxCoeff());
  const Eigen::MatrixXd diff = predicted_mm - goal_mm;
  const double span = std::max(diff.cwiseAbs().maxCoeff(), 1e-9);
  char scale[96];
  std::snprintf(scale, sizeof scale, "%.1f..%.1f mm, shared with predicted", lo, hi);
  char dscale[96];
  std::snprintf(dscale, sizeof dscale, "predicted - goal (+-%.1f mm)", span);
  std::vector<cv::Mat> panels = {titled(panel(mesh, goal_mm, lo, hi, cv::COLORMAP_VIRIDIS), std::string("goal (") + scale + ")"),
                                 titled(panel(mesh, predicted_mm, lo, hi, cv::COLORMAP_VIRIDIS), "predicted"),
                                 titled(panel(mesh, diff, -span, span, cv::COLORMAP_JET), dscale)};
  cv::Mat row;
  cv::hconcat(panels, row);
  std::filesystem::create_directories(path.parent_path());
  if (!cv::imwrite(path.string(), row)) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace hj::cli
