// Goal import from a CSV table of heights: one matrix row per line, comma
// separated, `nan` (any case) or an empty field = no data. The format of the
// DEMs in shared/data/dem; rows are kept in file order (row 0 = top).
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "shapes/goal_importer.h"

namespace hj {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string_view trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool is_nan_word(std::string_view s) {
  return s.size() == 3 && (s[0] | 0x20) == 'n' && (s[1] | 0x20) == 'a' && (s[2] | 0x20) == 'n';
}

// One field: a finite number, or NaN for an empty field or `nan`.
double parse_field(const std::filesystem::path& file, long line, long column, std::string_view text) {
  const std::string_view field = trimmed(text);
  if (field.empty() || is_nan_word(field)) return kNaN;
  std::string_view digits = field;
  if (digits.size() > 1 && digits.front() == '+') digits.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const std::string where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
  if (ec != std::errc() || end != digits.data() + digits.size())
    throw ImportError(file, where + "\"" + std::string(field) + "\" is not a number");
  if (!std::isfinite(value)) throw ImportError(file, where + "\"" + std::string(field) + "\" is not a finite number");
  return value;
}

ImportError too_many_values(const std::filesystem::path& file, const ImportOptions& options, long line) {
  return ImportError(file, "more than " + std::to_string(options.max_pixels) + " values (ImportOptions.max_pixels) by line " +
                               std::to_string(line));
}

class CsvImporter final : public GoalImporter {
 public:
  std::string name() const override { return "csv"; }
  std::vector<std::string> extensions() const override { return {".csv"}; }

  HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const override {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw ImportError(file, "the file cannot be opened for reading");
    std::vector<double> values;  // row-major
    long cols = 0, rows = 0, line_no = 0, first_blank = 0;
    bool any_valid = false;
    for (std::string line; std::getline(in, line);) {
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line_no == 1 && line.starts_with("\xEF\xBB\xBF")) line.erase(0, 3);  // UTF-8 byte order mark
      // Blank lines may only end the file.
      if (trimmed(line).empty()) {
        if (first_blank == 0) first_blank = line_no;
        continue;
      }
      if (first_blank != 0)
        throw ImportError(file, "line " + std::to_string(first_blank) +
                                    " is blank; write NaN for missing values (blank lines may only end the file)");
      long column = 0;
      for (std::size_t start = 0;;) {
        const std::size_t comma = line.find(',', start);
        const double v = parse_field(file, line_no, ++column, std::string_view(line).substr(start, comma - start));
        any_valid = any_valid || !std::isnan(v);
        // Counted as the fields come, so one endless line is stopped too.
        if (long(values.size()) >= options.max_pixels) throw too_many_values(file, options, line_no);
        values.push_back(v);
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
      if (rows == 0) cols = column;
      if (column != cols)
        throw ImportError(file, "line " + std::to_string(line_no) + " has " + std::to_string(column) +
                                    " values, the first row has " + std::to_string(cols) + " (rows must be equally long)");
      ++rows;
    }
    if (in.bad()) throw ImportError(file, "reading failed after line " + std::to_string(line_no));
    if (rows == 0) throw ImportError(file, "the file is empty (no data rows)");
    if (!any_valid) throw ImportError(file, "every value is NaN or empty (no data)");

    HeightMap map;
    map.z = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        values.data(), rows, cols);
    map.source = file.string();
    return map;
  }
};

}  // namespace

HJ_REGISTER_GOAL_IMPORTER(CsvImporter);

}  // namespace hj
