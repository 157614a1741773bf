// libFuzzer: the SRTM .hgt importer. A tile must be 1201 x 1201 samples, so
// the input fills one (repeated, or cut); its first 7 bytes, kept if they are
// letters or digits, name the tile (N37W122: the corner parsed from the name).
// Anything but ImportError escaping is a finding.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_folder.h"
#include "shapes/goal_importer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::string stem;
  for (std::size_t i = 0; i < size && i < 7; ++i)
    stem += std::isalnum(data[i]) ? char(data[i]) : 'x';
  constexpr std::size_t kTileBytes = 1201u * 1201u * 2u;
  std::string tile(kTileBytes, '\0');
  for (std::size_t k = 0; k < kTileBytes; ++k) tile[k] = char(data[k % size]);
  const auto file = hj::fuzz::folder() / (stem + ".hgt");
  hj::fuzz::write_file(file, tile);
  hj::ImportOptions options;
  options.max_pixels = 2'000'000;
  options.sidecar = false;
  try {
    hj::import_goal(file, options);
  } catch (const hj::ImportError&) {
  }
  std::filesystem::remove(file);
  return 0;
}
