// A small self-contained HTML page builder for the calibration reports:
// headings, paragraphs, tables, images referenced by relative path, and line
// or scatter plots drawn as inline SVG (no external resources).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace hj::cli {

struct SvgSeries {
  std::string name;
  std::vector<double> x, y;
  std::string colour = "#1f77b4";
  bool lines = true;    // join the points
  bool markers = true;
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<SvgSeries> series;
  std::vector<std::string> x_ticks;  // if set: category labels at x = 0, 1, ...
  double y_min = 0.0;                // the y axis starts here (0 for errors)
  // Horizontal reference line (e.g. the noise floor); drawn if label is set.
  double reference_y = 0.0;
  std::string reference_label;
};

std::string html_escape(const std::string& text);
std::string svg_plot(const Plot& plot, int width = 640, int height = 360);

class HtmlReport {
 public:
  explicit HtmlReport(std::string title);
  void heading(const std::string& text, int level = 2);
  void paragraph(const std::string& text);  // escaped
  void raw(const std::string& html);
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
  void image(const std::string& relative_path, const std::string& caption);
  // Writes the page; std::runtime_error naming the file if it cannot.
  void write(const std::filesystem::path& path) const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace hj::cli
