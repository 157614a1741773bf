// libFuzzer: the JSON sidecar (src/shapes/sidecar.cc) beside a small CSV
// map: the input is the sidecar's text. Anything but ImportError or a
// bad-argument error escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_folder.h"
#include "shapes/goal_importer.h"
#include "shapes/sidecar.h"

namespace {

// A 3 x 4 map read once without its sidecar.
const hj::HeightMap& base_map() {
  static const hj::HeightMap map = [] {
    const auto csv = hj::fuzz::folder() / "base.csv";
    hj::fuzz::write_file(csv, "1,2,3,4\n5,6,7,8\n9,10,11,12\n");
    hj::ImportOptions options;
    options.sidecar = false;
    return hj::import_goal(csv, options);
  }();
  return map;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto goal = hj::fuzz::folder() / "goal.csv";
  static const bool written = (hj::fuzz::write_file(goal, "1,2\n3,4\n"), true);
  (void)written;
  hj::fuzz::write_file(hj::fuzz::folder() / "goal.json", std::string(reinterpret_cast<const char*>(data), size));
  hj::HeightMap map = base_map();
  try {
    hj::apply_sidecar(goal, map);
  } catch (const hj::ImportError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
