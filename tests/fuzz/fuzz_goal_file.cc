// libFuzzer: one goal importer (HJ_FUZZ_EXTENSION: .csv, .png, .stl, .obj,
// .gltf, .ply) on arbitrary file contents, with a sidecar when the input
// holds a NUL (bytes after it become NAME.json). Anything but ImportError or
// a bad-argument error escaping is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "shapes/goal_importer.h"

namespace {

const std::filesystem::path& folder() {
  static const std::filesystem::path path = [] {
    auto p = std::filesystem::temp_directory_path() / ("hj-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p;
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const auto goal = folder() / ("goal" HJ_FUZZ_EXTENSION);
  const auto sidecar = folder() / "goal.json";
  const std::size_t nul = bytes.find('\0');
  std::ofstream(goal, std::ios::binary) << bytes.substr(0, nul);
  std::filesystem::remove(sidecar);
  if (nul != std::string::npos) std::ofstream(sidecar, std::ios::binary) << bytes.substr(nul + 1);
  hj::ImportOptions options;
  options.max_pixels = 1'000'000;
  options.mesh_resolution = 64;
  try {
    hj::import_goal(goal, options);
  } catch (const hj::ImportError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
