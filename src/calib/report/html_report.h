// A small self-contained HTML page builder for the calibration reports:
// headings, paragraphs, tables, embedded PNG images, and line
// or scatter plots (plot.h) drawn as inline SVG (no external resources).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "calib/report/plot.h"

namespace hj {

std::string html_escape(const std::string& text);
// printf-style formatting of one number (e.g. "%.3f") for the reports' text.
std::string format_number(double v, const char* format = "%.4g");
std::string svg_plot(const Plot& plot, int width = 640, int height = 360);

class HtmlReport {
 public:
  explicit HtmlReport(std::string title);
  void heading(const std::string& text, int level = 2);
  void paragraph(const std::string& text);  // escaped
  void raw(const std::string& html);
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
  // A PNG inside the page (a data: URI), so the page needs no other file.
  void embedded_png(const std::string& png, const std::string& caption, int width);
  // The whole page, and what has been added to its body.
  std::string html() const;
  const std::string& body() const { return body_; }
  // Writes the page; std::runtime_error naming the file if it cannot.
  void write(const std::filesystem::path& path) const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace hj
