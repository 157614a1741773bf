// Session datasets with absurd step counts are refused before the steps are
// read (an absurd array is refused by the mesh's point limit, calib_io_test).
#include <gtest/gtest.h>

#include <fstream>

#include "calib/session.h"
#include "expect_error.h"
#include "scratch_dir.h"

namespace hj {
namespace {

using namespace testing_support;

std::string session_json(int rows, int cols, int steps) {
  std::string s = R"({"format":"hapticjam.session/1","name":"big","device":{"rows":)" + std::to_string(rows) +
                  R"(,"cols":)" + std::to_string(cols) +
                  R"(,"cell_size_mm":38.0,"max_pressure_kpa":3.45},"grid":{"nx":77,"ny":58,"x0_mm":0,"y0_mm":0,)"
                  R"("dx_mm":2,"dy_mm":2},"steps":[)";
  for (int i = 0; i < steps; ++i) s += std::string(i ? "," : "") + R"({"op":"set_pressure","kpa":0.5})";
  return s + "]}";
}

TEST(SessionLimits, TooManyStepsAreRefusedBeforeTheyAreRead) {
  ScratchDir dir;
  std::ofstream(dir.path / "session.json") << session_json(3, 4, 100001);
  expect_error<SessionError>([&] { read_session(dir.path); }, {"session.json", "steps", "100001", "100000"});
}

}  // namespace
}  // namespace hj
