#include "shapes/goal_importer.h"

#include "shapes/sidecar.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace hj {

namespace {

std::vector<std::unique_ptr<GoalImporter>>& registry() {
  static std::vector<std::unique_ptr<GoalImporter>> importers;
  return importers;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

const GoalImporter* importer_for(const std::string& extension) {
  for (const auto& importer : registry()) {
    const auto exts = importer->extensions();
    if (std::find(exts.begin(), exts.end(), extension) != exts.end()) return importer.get();
  }
  return nullptr;
}

// Missing, not a file, empty or unreadable: the same message for every format.
void check_readable(const std::filesystem::path& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw ImportError(file, "no such file");
  if (!std::filesystem::is_regular_file(status)) throw ImportError(file, "not a regular file");
  if (std::filesystem::file_size(file, ec) == 0 && !ec) throw ImportError(file, "the file is empty");
  if (!std::ifstream(file, std::ios::binary)) throw ImportError(file, "the file cannot be opened for reading");
}

// What every importer promises: a non-empty map, finite or NaN values, at
// least one of them valid.
void check_result(const std::filesystem::path& file, const HeightMap& map) {
  if (map.z.size() == 0) throw ImportError(file, "it holds no values");
  if (map.z.array().isNaN().all()) throw ImportError(file, "every value is NaN (no data)");
  for (Eigen::Index k = 0; k < map.z.size(); ++k)
    if (std::isinf(map.z.data()[k])) throw ImportError(file, "it holds an infinite value");
}

}  // namespace

GoalImporter::~GoalImporter() = default;

void ImportOptions::validate() const {
  if (max_pixels <= 0)
    throw std::invalid_argument("ImportOptions.max_pixels must be a positive pixel count, got " +
                                std::to_string(max_pixels));
  if (mesh_up_axis != 0 && mesh_up_axis != 'x' && mesh_up_axis != 'y' && mesh_up_axis != 'z')
    throw std::invalid_argument("ImportOptions.mesh_up_axis must be 'x', 'y', 'z' (mesh_up_negative for -) or 0 (the sidecar's), got '" +
                                std::string(1, mesh_up_axis) + "'");
  if (hue && encoding != PixelEncoding::kGrey)
    throw std::invalid_argument("ImportOptions.hue and ImportOptions.encoding (terrain-rgb / terrarium) exclude each other");
  if (mesh_resolution <= 0)
    throw std::invalid_argument("ImportOptions.mesh_resolution must be a positive pixel count, got " +
                                std::to_string(mesh_resolution));
}

PixelEncoding parse_pixel_encoding(const std::string& name) {
  if (name == "grey" || name == "gray") return PixelEncoding::kGrey;
  if (name == "terrain-rgb") return PixelEncoding::kTerrainRgb;
  if (name == "terrarium") return PixelEncoding::kTerrarium;
  throw std::invalid_argument("unknown pixel encoding \"" + name + "\"; known: grey, terrain-rgb, terrarium");
}

void register_goal_importer(std::unique_ptr<GoalImporter> importer) {
  for (const auto& ext : importer->extensions()) {
    if (ext.size() < 2 || ext.front() != '.' || ext != lower(ext))
      throw std::logic_error("goal importer \"" + importer->name() + "\": extension \"" + ext +
                             "\" must be lower case and start with a dot");
    if (const GoalImporter* other = importer_for(ext))
      throw std::logic_error("goal importers \"" + other->name() + "\" and \"" + importer->name() +
                             "\" both claim \"" + ext + "\"");
  }
  registry().push_back(std::move(importer));
}

std::vector<std::string> known_goal_extensions() {
  std::vector<std::string> out;
  for (const auto& importer : registry())
    for (const auto& ext : importer->extensions()) out.push_back(ext);
  std::sort(out.begin(), out.end());
  return out;
}

HeightMap import_goal(const std::filesystem::path& file, const ImportOptions& options) {
  options.validate();
  const std::string ext = lower(file.extension().string());
  const GoalImporter* importer = importer_for(ext);
  if (importer == nullptr)
    throw ImportError(file, (ext.empty() ? std::string("no file extension") : "unknown extension \"" + ext + "\"") +
                                "; known goal formats: " + joined(known_goal_extensions()));
  check_readable(file);
  HeightMap map = importer->import(file, options);
  check_result(file, map);
  if (options.sidecar) apply_sidecar(file, map);
  return map;
}

}  // namespace hj
