// One description of a line or scatter plot, drawn by two renderers: PNG
// (plot_png.h, OpenCV, for the sweep's figures: the paper's Figs. 11 and 13)
// and inline SVG (html_report.h, for the calibration reports).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace hj {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // same length; non-finite y are skipped
  std::string colour;        // "#rrggbb"; empty: the palette's colour for its index
  bool lines = true;         // join the points (in order of x)
  bool markers = true;
};

struct PlotFit {  // y = slope x + intercept across the plot, dashed
  double slope = 0.0, intercept = 0.0;
  std::string label;
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  std::vector<std::string> x_ticks;  // if set: category labels at x = 0, 1, ...
  std::optional<double> y_min;       // the y axis starts here (0 for errors); unset: from the data
  // Horizontal reference line (e.g. the noise floor); drawn if label is set.
  double reference_y = 0.0;
  std::string reference_label;
  std::vector<PlotFit> fits;
};

// The series' colour, or the palette's (ten Tableau colours) for its index.
std::string series_colour(const PlotSeries& series, std::size_t index);

}  // namespace hj
