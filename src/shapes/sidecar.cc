#include "shapes/sidecar.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hj {
namespace {

void flip_rows(HeightMap& m) {
  m.z = m.z.colwise().reverse().eval();
  if (!m.georef) return;
  auto& gt = m.georef->geotransform;
  const double h = double(m.z.rows());
  gt[0] += h * gt[2];
  gt[3] += h * gt[5];
  gt[2] = -gt[2];
  gt[5] = -gt[5];
}

void flip_cols(HeightMap& m) {
  m.z = m.z.rowwise().reverse().eval();
  if (!m.georef) return;
  auto& gt = m.georef->geotransform;
  const double w = double(m.z.cols());
  gt[0] += w * gt[1];
  gt[3] += w * gt[4];
  gt[1] = -gt[1];
  gt[4] = -gt[4];
}

void transpose(HeightMap& m) {
  m.z = m.z.transpose().eval();
  if (!m.georef) return;
  auto& gt = m.georef->geotransform;
  std::swap(gt[1], gt[2]);
  std::swap(gt[4], gt[5]);
}

std::string without_blanks(const std::string& s) {
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '\t') out += c;
  return out;
}

}  // namespace

HeightMap reorient(const HeightMap& map, const std::string& numpy_expression) {
  const std::string expr = without_blanks(numpy_expression.substr(0, numpy_expression.find_first_of("(#")));
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("orientation \"" + numpy_expression + "\": " + what +
                                "; understood: a, .T and the slices [::-1], [::-1, :], [:, ::-1], [::-1, ::-1]");
  };
  if (expr.empty() || expr[0] != 'a') fail("must start with the array name a");
  HeightMap out = map;
  for (std::size_t i = 1; i < expr.size();) {
    if (expr.compare(i, 2, ".T") == 0) {
      transpose(out);
      i += 2;
      continue;
    }
    if (expr[i] != '[') fail("\"" + expr.substr(i) + "\" is not understood");
    const std::size_t close = expr.find(']', i);
    if (close == std::string::npos) fail("a [ is not closed");
    // The slice may contain a blank after its comma: take it from the full text.
    std::string slice = expr.substr(i + 1, close - i - 1);
    const std::size_t comma = slice.find(',');
    const std::string rows = slice.substr(0, comma);
    const std::string cols = comma == std::string::npos ? ":" : slice.substr(comma + 1);
    for (const auto& [part, flip] : {std::pair{rows, &flip_rows}, std::pair{cols, &flip_cols}}) {
      if (part == "::-1") flip(out);
      else if (part != ":" && part != "::") fail("slice \"" + part + "\" is not understood");
    }
    i = close + 1;
  }
  return out;
}

namespace {

// NAME.json beside `goal_file`, parsed, with what to throw for it; empty
// when there is none.
struct Sidecar {
  std::filesystem::path goal_file, file;
  nlohmann::json doc;
  [[noreturn]] void fail(const std::string& what) const {
    throw ImportError(goal_file, "its sidecar \"" + file.string() + "\" " + what +
                                     " (ImportOptions.sidecar = false / --no-sidecar ignores it)");
  }
};

std::optional<Sidecar> read_sidecar(const std::filesystem::path& goal_file) {
  Sidecar out{goal_file, goal_file.parent_path() / (goal_file.stem().string() + ".json"), {}};
  if (goal_file.extension() == ".json" || !std::filesystem::is_regular_file(out.file)) return std::nullopt;
  try {
    std::ifstream in(out.file);
    out.doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    out.fail(std::string("is not valid JSON: ") + e.what());
  }
  return out;
}

}  // namespace

void apply_sidecar(const std::filesystem::path& goal_file, HeightMap& map) {
  const std::optional<Sidecar> sidecar = read_sidecar(goal_file);
  if (!sidecar || !sidecar->doc.is_object()) return;
  const nlohmann::json& doc = sidecar->doc;
  const auto fail = [&](const std::string& what) { sidecar->fail(what); };
  try {
    if (!map.georef && doc.contains("georef") && doc["georef"].is_object() && doc["georef"].contains("geotransform")) {
      const auto& g = doc.at("georef");
      const auto gt = g.at("geotransform").get<std::vector<double>>();
      if (gt.size() != 6) fail("has a georef.geotransform of " + std::to_string(gt.size()) + " numbers, not 6");
      GeoReference ref;
      std::copy(gt.begin(), gt.end(), ref.geotransform.begin());
      const std::string crs = g.value("crs", std::string("WGS 84"));
      ref.crs_wkt = (crs == "WGS 84" || crs == "WGS84") ? "EPSG:4326" : crs;
      map.georef = ref;
    }
    if (map.units.empty() && doc.contains("units") && doc["units"].is_string()) {
      const std::string u = doc["units"];
      if (u.starts_with("metre") || u.starts_with("meter")) map.units = "m";
    }
    if (doc.contains("orientation") && doc["orientation"].is_object() && doc["orientation"].contains("north_up_numpy")) {
      const std::string expr = doc["orientation"].at("north_up_numpy").get<std::string>();
      map = reorient(map, expr);
      if (without_blanks(expr.substr(0, expr.find_first_of("(#"))) != "a")
        map.source += " [north-up by " + sidecar->file.filename().string() + "]";
    }
  } catch (const nlohmann::json::exception& e) {
    fail(std::string("has a key of the wrong type: ") + e.what());
  } catch (const std::invalid_argument& e) {
    fail(std::string("has an orientation that is not understood: ") + e.what());
  }
}

std::optional<std::pair<char, bool>> sidecar_up_axis(const std::filesystem::path& mesh_file) {
  const std::optional<Sidecar> sidecar = read_sidecar(mesh_file);
  if (!sidecar || !sidecar->doc.is_object() || !sidecar->doc.contains("up_axis")) return std::nullopt;
  const nlohmann::json& doc = sidecar->doc;
  const auto fail = [&](const std::string& what) { sidecar->fail(what); };
  if (!doc["up_axis"].is_string()) fail("has an \"up_axis\" that is not a string");
  const std::string text = doc["up_axis"];
  std::size_t at = 0;
  bool negative = false;
  if (at < text.size() && (text[at] == '+' || text[at] == '-')) negative = text[at++] == '-';
  const char axis = at < text.size() ? char(std::tolower(static_cast<unsigned char>(text[at]))) : 0;
  const bool ends = at + 1 == text.size() || !std::isalnum(static_cast<unsigned char>(text[at + 1]));
  if ((axis != 'x' && axis != 'y' && axis != 'z') || !ends)
    fail("has up_axis \"" + text + "\", not one of +x, -x, +y, -y, +z, -z");
  return std::make_pair(axis, negative);
}

}  // namespace hj
