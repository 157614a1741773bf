// libFuzzer: a mesh goal (HJ_FUZZ_EXTENSION: .gltf or .obj) imported from an
// upload folder, as the server does, with decoys beside the upload: a
// buffer, an image and a material library the input may name by "..", by
// absolute path or by URI. The input is the mesh; bytes after a NUL become
// the upload's second file ("buffer.bin" beside it). Opening any decoy is a
// finding (inotify watches the folder above the upload), as is anything but
// ImportError or a bad-argument error escaping.
#include <sys/inotify.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fuzz_folder.h"
#include "shapes/goal_importer.h"

namespace {

const std::filesystem::path& upload() {
  static const std::filesystem::path path = [] {
    const auto outside = hj::fuzz::folder();
    // A valid 3-vertex buffer, a 1 x 1 PNG and a material library: the decoys.
    hj::fuzz::write_file(outside / "secret.bin", std::string(36, '\0'));
    hj::fuzz::write_file(outside / "secret.png", std::string("\x89PNG\r\n\x1a\n", 8));
    hj::fuzz::write_file(outside / "secret.mtl", "newmtl m\nKd 1 0 0\n");
    auto p = outside / "upload";
    std::filesystem::create_directories(p);
    return p;
  }();
  return path;
}

// An inotify descriptor watching the folder above the upload for opens.
int watch() {
  static const int fd = [] {
    const int fd = inotify_init1(IN_NONBLOCK);
    if (fd < 0 || inotify_add_watch(fd, hj::fuzz::folder().c_str(), IN_OPEN) < 0) std::abort();
    return fd;
  }();
  return fd;
}

// Aborts if anything in the watched folder (not the upload itself) was opened.
void expect_nothing_opened_outside() {
  alignas(inotify_event) char buffer[4096];
  for (;;) {
    const ssize_t n = read(watch(), buffer, sizeof buffer);
    if (n <= 0) return;
    for (ssize_t at = 0; at < n;) {
      const auto* e = reinterpret_cast<const inotify_event*>(buffer + at);
      if (!(e->mask & IN_ISDIR) && e->len > 0) {
        std::fprintf(stderr, "the importer opened %s outside the upload\n", e->name);
        std::abort();
      }
      at += ssize_t(sizeof(inotify_event) + e->len);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const auto goal = upload() / ("goal" HJ_FUZZ_EXTENSION);
  const std::size_t nul = bytes.find('\0');
  hj::fuzz::write_file(goal, bytes.substr(0, nul));
  hj::fuzz::write_file(upload() / "buffer.bin", nul == std::string::npos ? std::string() : bytes.substr(nul + 1));
  expect_nothing_opened_outside();  // the harness's own writes
  hj::ImportOptions options;
  options.max_pixels = 1'000'000;
  options.mesh_resolution = 64;
  options.sidecar = false;
  try {
    hj::import_goal(goal, options);
  } catch (const hj::ImportError&) {
  } catch (const std::invalid_argument&) {
  }
  expect_nothing_opened_outside();
  return 0;
}
