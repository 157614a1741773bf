#include "calib/frame_csv.h"

#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "calib/session.h"

namespace hj {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The lines of `text`, without their "\n" (or "\r\n"); a final newline ends
// the last line rather than starting an empty one.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return lines;
}

// Parses one field: a number, or "nan" (any case) / empty for NaN. Returns
// false on anything else, infinities included.
bool parse_height(std::string_view field, double& value) {
  field = trim(field);
  if (field.empty()) {
    value = kNaN;
    return true;
  }
  if (field.size() > 1 && field.front() == '+' && field[1] != '-') field.remove_prefix(1);
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc() || end != field.data() + field.size()) return false;
  if (std::isnan(value)) value = kNaN;  // "nan", "NaN", "-nan"
  return !std::isinf(value);
}

// Shortest text that is the height to 1e-4 mm: "-12.3457", "0", "nan".
std::string format_height(double v) {
  if (std::isnan(v)) return "nan";
  char buffer[400];  // a fixed-notation double has at most 309 integer digits
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::fixed, 4);
  if (ec != std::errc()) throw std::logic_error("format_height: buffer too small");
  std::string text(buffer, end);
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  if (text == "-0") text = "0";
  return text;
}

std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return tmp;
}

}  // namespace

Eigen::MatrixXd read_frame_csv(const std::filesystem::path& path, int expected_ny, int expected_nx) {
  if (expected_ny < 1 || expected_nx < 1)
    throw std::invalid_argument("read_frame_csv: expected shape " + std::to_string(expected_ny) + " x " +
                                std::to_string(expected_nx) + " is empty");
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    throw SessionError(file + ": cannot open frame (" +
                       (std::filesystem::exists(path, ec) ? "not readable" : "no such file") + ")");
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw SessionError(file + ": read error");

  const std::vector<std::string_view> lines = split_lines(text);
  if (static_cast<long long>(lines.size()) != expected_ny)
    throw SessionError(file + ": " + std::to_string(lines.size()) + " lines, expected " +
                       std::to_string(expected_ny) + " (grid ny; the frame must be ny x nx = " +
                       std::to_string(expected_ny) + " x " + std::to_string(expected_nx) + ")");

  Eigen::MatrixXd heights_mm(expected_ny, expected_nx);
  for (int iy = 0; iy < expected_ny; ++iy) {
    std::string_view rest = lines[iy];
    int ix = 0;
    for (;; ++ix) {
      const std::size_t comma = rest.find(',');
      const std::string_view field = rest.substr(0, comma);
      if (ix < expected_nx && !parse_height(field, heights_mm(iy, ix)))
        throw SessionError(file + ": line " + std::to_string(iy + 1) + ", column " + std::to_string(ix + 1) +
                           ": \"" + std::string(trim(field).substr(0, 40)) +
                           "\" is not a number (nor \"nan\" or empty)");
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (ix + 1 != expected_nx)
      throw SessionError(file + ": line " + std::to_string(iy + 1) + ": " + std::to_string(ix + 1) +
                         " values, expected " + std::to_string(expected_nx) + " (grid nx)");
  }
  return heights_mm;
}

void write_frame_csv(const std::filesystem::path& path, const Eigen::MatrixXd& heights_mm) {
  const std::string file = path.string();
  if (heights_mm.size() == 0) throw std::invalid_argument(file + ": cannot write an empty frame");

  std::string text;
  text.reserve(static_cast<std::size_t>(heights_mm.size()) * 8);
  for (Eigen::Index iy = 0; iy < heights_mm.rows(); ++iy) {
    for (Eigen::Index ix = 0; ix < heights_mm.cols(); ++ix) {
      const double v = heights_mm(iy, ix);
      if (std::isinf(v))
        throw std::invalid_argument(file + ": height at row " + std::to_string(iy) + ", column " +
                                    std::to_string(ix) + " is infinite");
      if (ix > 0) text += ',';
      text += format_height(v);
    }
    text += '\n';
  }

  std::error_code ec;
  if (path.has_parent_path()) {
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) throw std::runtime_error(file + ": cannot create its folder: " + ec.message());
  }
  const std::filesystem::path tmp = temporary_beside(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error(file + ": cannot write the frame (via " + tmp.string() + ")");
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(file + ": cannot replace it with the written frame: " + ec.message());
  }
}

}  // namespace hj
