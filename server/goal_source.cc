#include "goal_source.h"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

#include "proto_convert.h"
#include "shapes/goal_importer.h"
#include "shapes/region.h"

namespace hj::server {

namespace {

// A file holding `bytes` with the extension of `file_name` (the importer
// picks the format by it), alone in a fresh private folder (0700) with its
// sidecar, so an importer confined to the file's folder (a mesh naming other
// files) reaches nothing but the upload; removed on destruction.
class TemporaryGoalFile {
 public:
  TemporaryGoalFile(const std::string& bytes, const std::string& file_name, const std::string& sidecar) {
    std::string folder = (std::filesystem::temp_directory_path() / "hj-goal-XXXXXX").string();
    if (::mkdtemp(folder.data()) == nullptr)
      throw std::runtime_error("cannot make a temporary folder for the goal in " +
                               std::filesystem::temp_directory_path().string());
    folder_ = folder;
    path_ = folder_ / ("goal" + std::filesystem::path(file_name).extension().string());
    try {
      write(path_, bytes, "the goal");
      // Beside it as NAME.json, where the importer looks for a sidecar.
      if (!sidecar.empty()) write(std::filesystem::path(path_).replace_extension(".json"), sidecar, "its sidecar");
    } catch (...) {
      std::error_code ignored;
      std::filesystem::remove_all(folder_, ignored);
      throw;
    }
  }
  ~TemporaryGoalFile() {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }
  TemporaryGoalFile(const TemporaryGoalFile&) = delete;
  TemporaryGoalFile& operator=(const TemporaryGoalFile&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  static void write(const std::filesystem::path& file, const std::string& bytes, const char* what) {
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) throw std::runtime_error(std::string("cannot write ") + what + " to the temporary file " + file.string());
  }

  std::filesystem::path folder_;
  std::filesystem::path path_;
};

HeightMap import_bytes(const hapticjam::v1::GoalFile& file, const ImportOptions& options) {
  if (file.file_name().empty())
    throw std::invalid_argument("goal.file.file_name is empty: its extension names the format (e.g. \"part.stl\")");
  if (file.content().empty()) throw std::invalid_argument("goal.file.content is empty");
  if (std::filesystem::path(file.file_name()).extension() == ".json")
    throw std::invalid_argument("goal.file.file_name \"" + file.file_name() +
                                "\": a .json file is a sidecar; send it as goal.file.sidecar_json");
  const TemporaryGoalFile temporary(file.content(), file.file_name(), file.sidecar_json());
  try {
    HeightMap map = import_goal(temporary.path(), options);
    map.source = file.file_name();
    return map;
  } catch (const ImportError& e) {
    // Name the client's file, not our temporary copy.
    std::string what = e.what();
    const std::string tmp = temporary.path().string();
    for (auto at = what.find(tmp); at != std::string::npos; at = what.find(tmp))
      what.replace(at, tmp.size(), file.file_name());
    const std::string side = std::filesystem::path(temporary.path()).replace_extension(".json").string();
    const std::string side_name = std::filesystem::path(file.file_name()).replace_extension(".json").string();
    for (auto at = what.find(side); at != std::string::npos; at = what.find(side))
      what.replace(at, side.size(), side_name);
    const std::string prefix = "cannot import goal \"" + file.file_name() + "\": ";
    throw ImportError(file.file_name(), what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what);
  }
}

}  // namespace

void MapStore::add(const std::string& name, const std::filesystem::path& file, const ServerLimits& limits) {
  if (name.empty()) throw std::invalid_argument("--map needs NAME=FILE, the name is empty");
  if (maps_.count(name)) throw std::invalid_argument("--map \"" + name + "\" given twice");
  ImportOptions options;
  options.max_pixels = limits.max_goal_pixels;
  maps_.emplace(name, import_goal(file, options));
}

const HeightMap* MapStore::find(const std::string& name) const {
  const auto found = maps_.find(name);
  return found == maps_.end() ? nullptr : &found->second;
}

std::vector<std::string> MapStore::names() const {
  std::vector<std::string> out;
  for (const auto& [name, map] : maps_) out.push_back(name);
  return out;
}

HeightMap load_goal(const hapticjam::v1::Goal& goal, const MapStore& maps, const ServerLimits& limits) {
  const ImportOptions options = import_options_from_proto(goal.options(), limits);
  HeightMap map;
  switch (goal.source_case()) {
    case hapticjam::v1::Goal::kFile: map = import_bytes(goal.file(), options); break;
    case hapticjam::v1::Goal::kMapName: {
      const HeightMap* found = maps.find(goal.map_name());
      if (!found) {
        std::string known;
        for (const auto& n : maps.names()) known += (known.empty() ? "" : ", ") + n;
        throw std::invalid_argument("goal.map_name \"" + goal.map_name() + "\" is not a map of this server (known: " +
                                    (known.empty() ? "none" : known) + ")");
      }
      map = *found;
      break;
    }
    case hapticjam::v1::Goal::SOURCE_NOT_SET: throw std::invalid_argument("goal has neither file nor map_name");
  }
  if (goal.has_region()) {
    const auto& r = goal.region();
    map = crop(map, Region{r.x0(), r.y0(), r.x1(), r.y1(), !r.pixels()});
  }
  return map;
}

}  // namespace hj::server
