#include "calib/report/html_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "calib/report/report_file.h"

namespace hj {

std::string format_number(double v, const char* format) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

namespace {

std::string fmt(double v) { return format_number(v); }

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string svg_plot(const Plot& plot, int width, int height) {
  const double left = 64, right = 160, top = 30, bottom = 48;
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_hi = -x_lo, y_data_lo = x_lo;
  for (const auto& s : plot.series)
    for (size_t i = 0; i < s.x.size(); ++i) {
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      if (std::isfinite(s.y[i])) y_hi = std::max(y_hi, s.y[i]), y_data_lo = std::min(y_data_lo, s.y[i]);
    }
  if (!plot.reference_label.empty()) y_hi = std::max(y_hi, plot.reference_y);
  if (!std::isfinite(x_lo)) x_lo = 0, x_hi = 1, y_hi = 1;
  if (x_hi <= x_lo) x_hi = x_lo + 1;
  const double y_lo = plot.y_min.value_or(std::isfinite(y_data_lo) ? y_data_lo : 0.0);
  y_hi = y_lo + (y_hi - y_lo) * 1.1;
  if (y_hi <= y_lo) y_hi = y_lo + 1;
  const double pad = plot.x_ticks.empty() ? 0.0 : 0.5;
  auto px = [&](double x) { return left + (x - x_lo + pad) / (x_hi - x_lo + 2 * pad) * (width - left - right); };
  auto py = [&](double y) { return top + (1.0 - (y - y_lo) / (y_hi - y_lo)) * (height - top - bottom); };
  std::string svg = "<svg xmlns='http://www.w3.org/2000/svg' width='" + std::to_string(width) + "' height='" +
                    std::to_string(height) + "' font-family='sans-serif' font-size='11'>";
  svg += "<text x='" + fmt(left) + "' y='16' font-size='13'>" + html_escape(plot.title) + "</text>";
  // Axes with five y ticks.
  svg += "<line x1='" + fmt(left) + "' y1='" + fmt(py(y_lo)) + "' x2='" + fmt(width - right) + "' y2='" +
         fmt(py(y_lo)) + "' stroke='black'/>";
  svg += "<line x1='" + fmt(left) + "' y1='" + fmt(top) + "' x2='" + fmt(left) + "' y2='" + fmt(py(y_lo)) +
         "' stroke='black'/>";
  for (int k = 0; k <= 4; ++k) {
    const double y = y_lo + (y_hi - y_lo) * k / 4.0;
    svg += "<text x='" + fmt(left - 6) + "' y='" + fmt(py(y) + 4) + "' text-anchor='end'>" + fmt(y) + "</text>";
  }
  if (plot.x_ticks.empty()) {
    for (int k = 0; k <= 4; ++k) {
      const double x = x_lo + (x_hi - x_lo) * k / 4.0;
      svg += "<text x='" + fmt(px(x)) + "' y='" + fmt(py(y_lo) + 16) + "' text-anchor='middle'>" + fmt(x) + "</text>";
    }
  } else {
    for (size_t k = 0; k < plot.x_ticks.size(); ++k)
      svg += "<text x='" + fmt(px(static_cast<double>(k))) + "' y='" + fmt(py(y_lo) + 16) +
             "' text-anchor='middle'>" + html_escape(plot.x_ticks[k]) + "</text>";
  }
  svg += "<text x='" + fmt((left + width - right) / 2) + "' y='" + fmt(height - 8.0) + "' text-anchor='middle'>" +
         html_escape(plot.x_label) + "</text>";
  svg += "<text x='14' y='" + fmt((top + height - bottom) / 2) + "' transform='rotate(-90 14 " +
         fmt((top + height - bottom) / 2) + ")' text-anchor='middle'>" + html_escape(plot.y_label) + "</text>";
  if (!plot.reference_label.empty()) {
    svg += "<line x1='" + fmt(left) + "' y1='" + fmt(py(plot.reference_y)) + "' x2='" + fmt(width - right) + "' y2='" +
           fmt(py(plot.reference_y)) + "' stroke='grey' stroke-dasharray='5,4'/>";
    svg += "<text x='" + fmt(width - right + 4) + "' y='" + fmt(py(plot.reference_y) + 4) + "' fill='grey'>" +
           html_escape(plot.reference_label) + "</text>";
  }
  for (const PlotFit& f : plot.fits)
    svg += "<line x1='" + fmt(px(x_lo)) + "' y1='" + fmt(py(f.slope * x_lo + f.intercept)) + "' x2='" + fmt(px(x_hi)) +
           "' y2='" + fmt(py(f.slope * x_hi + f.intercept)) + "' stroke='black' stroke-dasharray='7,5'><title>" +
           html_escape(f.label) + "</title></line>";
  int legend = 0;
  for (const auto& s : plot.series) {
    const std::string colour = series_colour(s, static_cast<size_t>(legend));
    std::string points;
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.y[i])) points += fmt(px(s.x[i])) + "," + fmt(py(s.y[i])) + " ";
    if (s.lines) svg += "<polyline fill='none' stroke='" + colour + "' stroke-width='2' points='" + points + "'/>";
    if (s.markers)
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i]))
          svg += "<circle cx='" + fmt(px(s.x[i])) + "' cy='" + fmt(py(s.y[i])) + "' r='3' fill='" + colour + "'/>";
    const double ly = top + 14.0 * legend++;
    svg += "<rect x='" + fmt(width - right + 4) + "' y='" + fmt(ly - 8) + "' width='10' height='10' fill='" + colour +
           "'/><text x='" + fmt(width - right + 18) + "' y='" + fmt(ly + 1) + "'>" + html_escape(s.name) + "</text>";
  }
  return svg + "</svg>";
}

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::heading(const std::string& text, int level) {
  const std::string tag = "h" + std::to_string(std::clamp(level, 1, 4));
  body_ += "<" + tag + ">" + html_escape(text) + "</" + tag + ">\n";
}
void HtmlReport::paragraph(const std::string& text) { body_ += "<p>" + html_escape(text) + "</p>\n"; }
void HtmlReport::raw(const std::string& html) { body_ += html + "\n"; }

void HtmlReport::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table><tr>";
  for (const auto& h : header) body_ += "<th>" + html_escape(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& row : rows) {
    body_ += "<tr>";
    for (const auto& cell : row) body_ += "<td>" + html_escape(cell) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::embedded_png(const std::string& png, const std::string& caption, int width) {
  body_ += "<figure><img src='data:image/png;base64," + base64(png) + "' width='" + std::to_string(width) +
           "' alt='" + html_escape(caption) + "'><figcaption>" + html_escape(caption) + "</figcaption></figure>\n";
}

std::string HtmlReport::html() const {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>" << html_escape(title_)
      << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:1em auto}"
         "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}"
         "figure{display:inline-block;margin:4px}figcaption{font-size:12px}</style></head>\n<body>\n<h1>"
      << html_escape(title_) << "</h1>\n"
      << body_ << "</body></html>\n";
  return out.str();
}

void HtmlReport::write(const std::filesystem::path& path) const { write_file(path, html()); }

}  // namespace hj
