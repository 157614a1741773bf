// libFuzzer: one goal importer (HJ_FUZZ_EXTENSION: .csv, .png, .tif, .stl,
// .obj, .gltf, .glb, .ply, .3mf; HJ_FUZZ_ENCODING: a PNG's pixel encoding,
// "terrain-rgb" or "terrarium") on arbitrary file contents, with a sidecar
// when the input holds a NUL (bytes after it become NAME.json). Anything but
// ImportError or a bad-argument error escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_folder.h"
#include "shapes/goal_importer.h"

#ifndef HJ_FUZZ_ENCODING
#define HJ_FUZZ_ENCODING "grey"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const auto goal = hj::fuzz::folder() / ("goal" HJ_FUZZ_EXTENSION);
  const auto sidecar = hj::fuzz::folder() / "goal.json";
  const std::size_t nul = bytes.find('\0');
  hj::fuzz::write_file(goal, bytes.substr(0, nul));
  std::filesystem::remove(sidecar);
  if (nul != std::string::npos) hj::fuzz::write_file(sidecar, bytes.substr(nul + 1));
  hj::ImportOptions options;
  options.max_pixels = 1'000'000;
  options.mesh_resolution = 64;
  options.encoding = hj::parse_pixel_encoding(HJ_FUZZ_ENCODING);
  try {
    hj::import_goal(goal, options);
  } catch (const hj::ImportError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
