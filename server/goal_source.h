// Goals as the server receives them: a file's bytes (imported through a
// temporary file by the library's importer for its extension) or a map named
// at start-up, then cropped to the requested region.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "hapticjam/v1/goal.pb.h"
#include "server_limits.h"
#include "shapes/height_map.h"

namespace hj::server {

// Maps given with --map NAME=FILE, imported once at start-up.
class MapStore {
 public:
  // @throws hj::ImportError, std::invalid_argument naming the map and file.
  void add(const std::string& name, const std::filesystem::path& file, const ServerLimits& limits);
  // nullptr if there is no such map.
  const HeightMap* find(const std::string& name) const;
  std::vector<std::string> names() const;

 private:
  std::map<std::string, HeightMap> maps_;
};

// The goal a request names, cropped to its region.
// @throws std::invalid_argument (no source, an unknown map, a bad region or
//         option) or hj::ImportError naming the client's file name (a
//         malformed file, one over a limit).
HeightMap load_goal(const hapticjam::v1::Goal& goal, const MapStore& maps, const ServerLimits& limits);

}  // namespace hj::server
