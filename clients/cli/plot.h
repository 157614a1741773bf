// Small line / scatter plots drawn with OpenCV, for the sweep's figures
// (the paper's Figs. 11 and 13).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace hj::cli {

struct PlotSeries {
  std::string label;
  std::vector<std::pair<double, double>> points;  // (x, y)
  bool lines = true;                             // joined in order of x, else markers only
};

struct PlotLine {  // y = slope x + intercept across the plot, dashed
  double slope = 0.0, intercept = 0.0;
  std::string label;
};

// Writes a PNG: axes with ticks, each series in its own colour with a
// legend, optional fitted lines.
void write_plot_png(const std::filesystem::path& file, const std::string& title, const std::string& x_label,
                    const std::string& y_label, const std::vector<PlotSeries>& series,
                    const std::vector<PlotLine>& fits = {});

}  // namespace hj::cli
