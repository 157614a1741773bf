// Goal importers, chosen by file extension. Each importer's .cc registers
// itself with HJ_REGISTER_GOAL_IMPORTER, so a new goal format is one new file
// in src/shapes/ (docs/architecture.md, "Where new things go").
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "shapes/height_map.h"

namespace hj {

// How a PNG's pixels encode height. A PNG cannot say which, so it is the
// caller's choice (plan --encoding).
enum class PixelEncoding {
  kGrey,        // grey level (or luminance, or hue with ImportOptions::hue) = height
  kTerrainRgb,  // Mapbox Terrain-RGB: h = -10000 + (R 65536 + G 256 + B) 0.1 m
  kTerrarium,   // Mapzen/AWS Terrarium: h = R 256 + G + B / 256 - 32768 m
};

// "grey", "terrain-rgb" or "terrarium"; std::invalid_argument otherwise.
PixelEncoding parse_pixel_encoding(const std::string& name);

struct ImportOptions {
  // Colour topographic map: height from hue, red-orange high, blue-purple low
  // (image_importer.cc documents the mapping). Off: colour -> luminance.
  bool hue = false;
  // PNG tiles of elevation packed into RGB (terrain_rgb.h); kGrey otherwise.
  // Only with hue off.
  PixelEncoding encoding = PixelEncoding::kGrey;
  // Read NAME.json beside the goal, if there is one (sidecar.h): its
  // "orientation" turns the map north-up, its "georef" georeferences a CSV.
  bool sidecar = true;
  // Refuse images or tables with more values than this (memory guard).
  long max_pixels = 50'000'000;
  // Meshes (mesh_importer.cc): the model axis that points up, 'x', 'y' or 'z',
  // negated when mesh_up_negative; the mesh is rotated so it becomes +z.
  // 0: the sidecar's "up_axis" when sidecar is on and NAME.json has one
  // (sidecar_up_axis), else +z.
  char mesh_up_axis = 0;
  bool mesh_up_negative = false;
  // Meshes: pixels along the longer horizontal side of the top view; its
  // square must not exceed max_pixels.
  int mesh_resolution = 256;

  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// One file format. import() returns a map with at least one valid value or
// throws ImportError; it may assume the file exists and options are valid.
class GoalImporter {
 public:
  virtual ~GoalImporter();
  virtual std::string name() const = 0;
  // Lower case, with the dot: {".png", ".tif"}.
  virtual std::vector<std::string> extensions() const = 0;
  virtual HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const = 0;
};

// Throws std::logic_error if another importer already claims one of its extensions.
void register_goal_importer(std::unique_ptr<GoalImporter> importer);

// Every registered extension, sorted: {".csv", ".png", ...}.
std::vector<std::string> known_goal_extensions();

// Imports a goal with the importer for its extension (case-insensitive).
// @throws ImportError on an unknown extension (listing the known ones), a
//         missing, unreadable or empty file, a malformed one, or one with no
//         valid (non-NaN) value; std::invalid_argument on bad options.
HeightMap import_goal(const std::filesystem::path& file, const ImportOptions& options = {});

namespace detail {
struct GoalImporterRegistration {
  explicit GoalImporterRegistration(std::unique_ptr<GoalImporter> importer) {
    register_goal_importer(std::move(importer));
  }
};
}  // namespace detail

}  // namespace hj

#define HJ_REGISTER_GOAL_IMPORTER_CONCAT2(a, b) a##b
#define HJ_REGISTER_GOAL_IMPORTER_CONCAT(a, b) HJ_REGISTER_GOAL_IMPORTER_CONCAT2(a, b)
// In an importer's .cc: HJ_REGISTER_GOAL_IMPORTER(CsvImporter); the program
// must link hj_goals whole-archive, or the linker drops the registrar.
#define HJ_REGISTER_GOAL_IMPORTER(Class)                                                      \
  static const ::hj::detail::GoalImporterRegistration HJ_REGISTER_GOAL_IMPORTER_CONCAT(       \
      hj_goal_importer_registration_, __LINE__)(std::make_unique<Class>())
