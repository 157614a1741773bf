#include "calib/report/residual_image.h"

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "calib/report/report_file.h"

namespace hj {

namespace {

constexpr int kPixelsPerSample = 6;
constexpr int kTitleHeight = 28;
constexpr int kLegendWidth = 90;

// Blue (-1) .. white (0) .. red (+1), as BGR.
cv::Vec3b diverging(double t) {
  t = std::clamp(t, -1.0, 1.0);
  const cv::Vec3d white(255, 255, 255), blue(172, 102, 33), red(43, 24, 178);
  const cv::Vec3d end = t < 0 ? blue : red;
  const double a = std::abs(t);
  const cv::Vec3d c = white * (1.0 - a) + end * a;
  return {cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]), cv::saturate_cast<uchar>(c[2])};
}

}  // namespace

std::string residual_png(const Session& session, const Eigen::MatrixXd& residual_mm, double scale_mm,
                         const std::vector<std::pair<int, int>>& pinned, const std::string& title) {
  const int ny = static_cast<int>(residual_mm.rows()), nx = static_cast<int>(residual_mm.cols());
  const int map_w = nx * kPixelsPerSample, map_h = ny * kPixelsPerSample;
  cv::Mat image(map_h + kTitleHeight + 8, map_w + kLegendWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat map = image(cv::Rect(0, kTitleHeight, map_w, map_h));
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) {
      const double r = residual_mm(iy, ix);
      const cv::Vec3b colour = std::isnan(r) ? cv::Vec3b(160, 160, 160) : diverging(r / scale_mm);
      cv::rectangle(map, cv::Rect(ix * kPixelsPerSample, (ny - 1 - iy) * kPixelsPerSample, kPixelsPerSample,
                                  kPixelsPerSample),
                    cv::Scalar(colour[0], colour[1], colour[2]), cv::FILLED);
    }
  // Sample (ix, iy) is drawn centred at pixel (ix + 0.5, ny - 1 - iy + 0.5) * kPixelsPerSample.
  auto to_pixel = [&](double x_mm, double y_mm) {
    const double fx = (x_mm - session.grid.x0_mm) / session.grid.dx_mm;
    const double fy = (y_mm - session.grid.y0_mm) / session.grid.dy_mm;
    return cv::Point(static_cast<int>(std::lround((fx + 0.5) * kPixelsPerSample)),
                     static_cast<int>(std::lround((ny - 1 - fy + 0.5) * kPixelsPerSample)));
  };
  const SessionDevice& d = session.device;
  const double s = d.cell_size_mm;
  for (int c = 0; c <= d.cols; ++c) cv::line(map, to_pixel(c * s, 0), to_pixel(c * s, d.rows * s), cv::Scalar(0, 0, 0), 1);
  for (int r = 0; r <= d.rows; ++r) cv::line(map, to_pixel(0, r * s), to_pixel(d.cols * s, r * s), cv::Scalar(0, 0, 0), 1);
  for (int a = 1; a < d.rows; ++a)
    for (int b = 1; b < d.cols; ++b) {
      const bool is_pinned = std::find(pinned.begin(), pinned.end(), std::pair<int, int>{a, b}) != pinned.end();
      cv::circle(map, to_pixel(b * s, a * s), 5, cv::Scalar(0, 0, 0), is_pinned ? cv::FILLED : 1, cv::LINE_AA);
    }
  cv::putText(image, title, {6, 19}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  // Legend: a vertical colour bar with five labelled ticks.
  const int bar_x = map_w + 12, bar_w = 16, bar_top = kTitleHeight + 10, bar_h = map_h - 20;
  for (int k = 0; k < bar_h; ++k) {
    const cv::Vec3b colour = diverging(1.0 - 2.0 * k / (bar_h - 1));
    cv::line(image, {bar_x, bar_top + k}, {bar_x + bar_w, bar_top + k}, cv::Scalar(colour[0], colour[1], colour[2]));
  }
  cv::rectangle(image, cv::Rect(bar_x, bar_top, bar_w, bar_h), cv::Scalar(0, 0, 0), 1);
  for (int k = 0; k <= 4; ++k) {
    char label[24];
    std::snprintf(label, sizeof label, "%+.1f", scale_mm * (1.0 - k / 2.0));
    const int y = bar_top + k * (bar_h - 1) / 4;
    cv::putText(image, label, {bar_x + bar_w + 4, y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
  }
  cv::putText(image, "mm", {bar_x, bar_top + bar_h + 14}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  std::vector<uchar> png;
  if (!cv::imencode(".png", image, png)) throw std::runtime_error("cannot encode the heat map \"" + title + "\"");
  return {png.begin(), png.end()};
}

void write_residual_png(const std::filesystem::path& path, const Session& session, const Eigen::MatrixXd& residual_mm,
                        double scale_mm, const std::vector<std::pair<int, int>>& pinned, const std::string& title) {
  write_file(path, residual_png(session, residual_mm, scale_mm, pinned, title));
}

}  // namespace hj
