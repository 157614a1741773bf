#include "remote_goal.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace hj::cli {

namespace v1 = ::hapticjam::v1;

namespace {

// "x0,y0,x1,y1": pixels if any value exceeds 1, else fractions (as `plan --region`).
v1::Region parse_region_flag(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  for (std::string field; std::getline(in, field, ',');) v.push_back(parse_number("--region", field));
  if (v.size() != 4) throw std::invalid_argument("--region needs x0,y0,x1,y1, got \"" + text + "\"");
  v1::Region r;
  r.set_x0(v[0]), r.set_y0(v[1]), r.set_x1(v[2]), r.set_y1(v[3]);
  r.set_pixels(v[0] > 1 || v[1] > 1 || v[2] > 1 || v[3] > 1);
  return r;
}

}  // namespace

bool GoalArgs::take(ArgCursor& cursor) {
  const std::string& a = cursor.arg();
  if (a == "--map") map_name = cursor.value();
  else if (a == "--rows") rows = parse_int(a, cursor.value(), 1, 1000);
  else if (a == "--cols") cols = parse_int(a, cursor.value(), 1, 1000);
  else if (a == "--segments") segments = parse_int(a, cursor.value(), 1, 1000);
  else if (a == "--cell-mm") {
    cell_mm = parse_number(a, cursor.value());
    if (!(cell_mm > 0)) throw std::invalid_argument("--cell-mm needs a positive number (mm)");
  } else if (a == "--planner") planner = cursor.value();
  else if (a == "--max-height-mm") {
    max_height_mm = parse_number(a, cursor.value());
    if (!(max_height_mm > 0)) throw std::invalid_argument("--max-height-mm needs a positive number (mm)");
  } else if (a == "--region") {
    region = cursor.value();
    parse_region_flag(region);
  } else if (a == "--heights") {
    const std::string& h = cursor.value();
    if (h != "absolute" && h != "scaled")
      throw std::invalid_argument("--heights needs scaled or absolute, got \"" + h + "\"");
    absolute_heights = h == "absolute";
  } else if (a == "--hue") hue = true;
  else if (a == "--no-sidecar") use_sidecar = false;
  else if (a == "--up-axis") {
    up_axis = cursor.value();
    const std::string axis = !up_axis.empty() && up_axis[0] == '-' ? up_axis.substr(1) : up_axis;
    if (axis != "x" && axis != "y" && axis != "z")
      throw std::invalid_argument("--up-axis needs x, y, z, -x, -y or -z, got \"" + up_axis + "\"");
  } else if (a == "--view-resolution") view_resolution = parse_int(a, cursor.value(), 1, 8192);
  else if (!a.empty() && a[0] != '-' && file.empty()) file = a;
  else return false;
  return true;
}

void GoalArgs::validate() const {
  if (file.empty() == map_name.empty()) throw std::invalid_argument("give a GOAL file or --map NAME (one of them)");
  if (rows == 0 || cols == 0) throw std::invalid_argument("--rows and --cols are required");
  if (absolute_heights && max_height_mm > 0)
    throw std::invalid_argument("--heights absolute and --max-height-mm exclude each other");
}

v1::ArraySpec GoalArgs::array() const {
  v1::ArraySpec a;
  a.set_rows(rows), a.set_cols(cols), a.set_segments(segments), a.set_cell_size_mm(cell_mm);
  return a;
}

v1::Goal GoalArgs::goal() const {
  v1::Goal g;
  if (!map_name.empty()) {
    g.set_map_name(map_name);
  } else {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read goal \"" + file + "\"");
    std::ostringstream bytes;
    bytes << in.rdbuf();
    g.mutable_file()->set_content(bytes.str());
    g.mutable_file()->set_file_name(std::filesystem::path(file).filename().string());
    // NAME.json beside the goal goes along, as a local plan would read it.
    const std::filesystem::path sidecar = std::filesystem::path(file).replace_extension(".json");
    if (use_sidecar && sidecar != std::filesystem::path(file) && std::filesystem::exists(sidecar)) {
      std::ifstream side(sidecar, std::ios::binary);
      std::ostringstream side_bytes;
      side_bytes << side.rdbuf();
      if (!side) throw std::runtime_error("cannot read the goal's sidecar \"" + sidecar.string() + "\"");
      g.mutable_file()->set_sidecar_json(side_bytes.str());
    }
  }
  if (!region.empty()) *g.mutable_region() = parse_region_flag(region);
  v1::GoalOptions* o = g.mutable_options();
  o->set_max_height_mm(max_height_mm);
  o->set_up_axis(up_axis);
  o->set_encoding(hue ? v1::HEIGHT_ENCODING_HUE : v1::HEIGHT_ENCODING_UNSPECIFIED);
  o->set_view_resolution(view_resolution);
  o->set_heights(absolute_heights ? v1::GOAL_HEIGHTS_ABSOLUTE : v1::GOAL_HEIGHTS_UNSPECIFIED);
  return g;
}

std::string GoalArgs::label() const {
  return map_name.empty() ? std::filesystem::path(file).filename().string() : "map " + map_name;
}

}  // namespace hj::cli
