// The inputs the fuzzers found (tests/fuzz/regressions/TARGET/), replayed as
// their harness does: each ends in a clean error, and leaves no file open.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "scratch_dir.h"
#include "shapes/goal_importer.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using testing_support::ScratchDir;

// tests/fuzz/regressions: __FILE__ is relative to the build folder, which holds the test binary.
fs::path regressions() {
  const fs::path source = fs::path(__FILE__).parent_path() / "fuzz" / "regressions";
  return source.is_absolute() ? source : fs::read_symlink("/proc/self/exe").parent_path() / source;
}

int open_files() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

// fuzz_mesh_upload_*: the input is the mesh, alone in its upload with an
// empty buffer.bin beside it.
TEST(FuzzRegressions, MeshUploadsEndCleanlyAndCloseTheirFiles) {
  const fs::path dir = regressions() / "fuzz_mesh_upload_gltf";
  int replayed = 0;
  for (const auto& input : fs::directory_iterator(dir)) {
    ScratchDir upload(input.path().stem().string());
    const fs::path goal = upload.path / "goal.gltf";
    fs::copy_file(input.path(), goal);
    std::ofstream(upload.path / "buffer.bin").close();
    const int before = open_files();
    ImportOptions options;
    options.sidecar = false;
    options.mesh_resolution = 64;
    try {
      import_goal(goal, options);
    } catch (const ImportError&) {
    } catch (const std::invalid_argument&) {
    }
    EXPECT_EQ(open_files(), before) << input.path() << " left a file open";
    ++replayed;
  }
  EXPECT_GT(replayed, 0);
}

}  // namespace
}  // namespace hj
