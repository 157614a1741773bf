#include "plot_png.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hj::cli {
namespace {

constexpr int kWidth = 900, kHeight = 600;
constexpr int kLeft = 80, kRight = 240, kTop = 50, kBottom = 70;

// "#rrggbb" as OpenCV's BGR.
cv::Scalar bgr(const std::string& hex) {
  const unsigned long rgb = hex.size() == 7 ? std::stoul(hex.substr(1), nullptr, 16) : 0;
  return cv::Scalar(rgb & 0xff, (rgb >> 8) & 0xff, (rgb >> 16) & 0xff);
}

double nice_step(double range) {
  const double raw = range / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10.0 * mag;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

}  // namespace

void write_plot_png(const std::filesystem::path& file, const Plot& plot) {
  const std::string &title = plot.title, &x_label = plot.x_label, &y_label = plot.y_label;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& s : plot.series)
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (std::isfinite(s.y[k])) x0 = std::min(x0, s.x[k]), x1 = std::max(x1, s.x[k]), y0 = std::min(y0, s.y[k]), y1 = std::max(y1, s.y[k]);
  if (!plot.reference_label.empty()) y0 = std::min(y0, plot.reference_y), y1 = std::max(y1, plot.reference_y);
  if (plot.y_min) y0 = *plot.y_min, y1 = std::max(y1, y0);
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 - x0 < 1e-9) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-9) y0 -= 0.05, y1 += 0.05;
  const double xs = nice_step(x1 - x0), ys = nice_step(y1 - y0);
  x0 = std::floor(x0 / xs) * xs, x1 = std::ceil(x1 / xs) * xs;
  y0 = std::floor(y0 / ys) * ys, y1 = std::ceil(y1 / ys) * ys;
  const int pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  const auto px = [&](double x) { return int(std::lround(kLeft + (x - x0) / (x1 - x0) * pw)); };
  const auto py = [&](double y) { return int(std::lround(kTop + ph - (y - y0) / (y1 - y0) * ph)); };

  cv::Mat img(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), grid(225, 225, 225);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (double x = x0; x <= x1 + 1e-9 * xs; x += xs) {
    cv::line(img, {px(x), kTop}, {px(x), kTop + ph}, grid, 1);
    cv::putText(img, fmt(x), {px(x) - 12, kTop + ph + 20}, font, 0.45, black, 1, cv::LINE_AA);
  }
  for (double y = y0; y <= y1 + 1e-9 * ys; y += ys) {
    cv::line(img, {kLeft, py(y)}, {kLeft + pw, py(y)}, grid, 1);
    cv::putText(img, fmt(y), {kLeft - 50, py(y) + 5}, font, 0.45, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {kLeft, kTop}, {kLeft + pw, kTop + ph}, black, 1);
  cv::putText(img, title, {kLeft, 30}, font, 0.65, black, 1, cv::LINE_AA);
  cv::putText(img, x_label, {kLeft + pw / 2 - 4 * int(x_label.size()), kHeight - 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::Mat ylab(30, 8 * int(y_label.size()) + 20, CV_8UC3, cv::Scalar(255, 255, 255)), rotated;
  cv::putText(ylab, y_label, {5, 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::rotate(ylab, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  if (rotated.rows <= kHeight) rotated.copyTo(img(cv::Rect(2, std::max(0, kTop + ph / 2 - rotated.rows / 2), rotated.cols, rotated.rows)));

  cv::Mat clip = img(cv::Rect(kLeft, kTop, pw + 1, ph + 1));
  const auto dashed = [&](cv::Point a, cv::Point b, const cv::Scalar& colour) {
    const double len = std::hypot(double(b.x - a.x), double(b.y - a.y));
    for (double t = 0; t < len; t += 12) {
      const double t1 = std::min(len, t + 7);
      cv::line(clip, a + (b - a) * (t / len), a + (b - a) * (t1 / len), colour, 1, cv::LINE_AA);
    }
  };
  if (!plot.reference_label.empty()) {
    const cv::Scalar grey(128, 128, 128);
    dashed({0, py(plot.reference_y) - kTop}, {pw, py(plot.reference_y) - kTop}, grey);
    cv::putText(img, plot.reference_label, {kLeft + pw + 8, py(plot.reference_y) + 5}, font, 0.45, grey, 1, cv::LINE_AA);
  }
  for (std::size_t k = 0; k < plot.fits.size(); ++k) {
    const auto& f = plot.fits[k];
    const cv::Point a{px(x0) - kLeft, py(f.slope * x0 + f.intercept) - kTop}, b{px(x1) - kLeft, py(f.slope * x1 + f.intercept) - kTop};
    dashed(a, b, black);
    cv::putText(img, f.label, {kLeft + 10, kTop + 20 + 20 * int(k)}, font, 0.5, black, 1, cv::LINE_AA);
  }
  for (std::size_t s = 0; s < plot.series.size(); ++s) {
    const PlotSeries& series = plot.series[s];
    const cv::Scalar colour = bgr(series_colour(series, s));
    std::vector<std::pair<double, double>> pts;
    for (std::size_t k = 0; k < series.x.size(); ++k)
      if (std::isfinite(series.y[k])) pts.emplace_back(series.x[k], series.y[k]);
    if (series.lines) std::sort(pts.begin(), pts.end());
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const cv::Point p{px(pts[k].first), py(pts[k].second)};
      if (series.markers) cv::circle(img, p, 4, colour, cv::FILLED, cv::LINE_AA);
      if (series.lines && k > 0) cv::line(img, {px(pts[k - 1].first), py(pts[k - 1].second)}, p, colour, 2, cv::LINE_AA);
    }
    const int ly = kTop + 10 + 22 * int(s);
    cv::circle(img, {kLeft + pw + 20, ly}, 5, colour, cv::FILLED, cv::LINE_AA);
    cv::putText(img, series.name.substr(0, 26), {kLeft + pw + 32, ly + 5}, font, 0.45, black, 1, cv::LINE_AA);
  }
  if (!cv::imwrite(file.string(), img)) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace hj::cli
