// The link's record of the device after acknowledged commands.
#include <gtest/gtest.h>

#include <algorithm>

#include "device/status_mirror.h"

namespace hj::device {
namespace {

TEST(StatusMirror, AcknowledgedCommandsChangeTheRecordAndVentClearsIt) {
  DeviceStatus s;
  s.rows = 3, s.cols = 4;
  s.cell_jammed.assign(12, 0);
  s.node_pinned.assign(20, 0);
  mirror_action(s, Action::set_pressure(1500.0));
  mirror_action(s, Action::jam(2, 3));
  mirror_action(s, Action::pin(3, 4));
  EXPECT_EQ(s.pressure_pa, 1500.0);
  EXPECT_EQ(s.cell_jammed[2 * 4 + 3], 1);
  EXPECT_EQ(s.node_pinned[3 * 5 + 4], 1);
  mirror_action(s, Action::unjam(2, 3));
  EXPECT_EQ(s.cell_jammed[2 * 4 + 3], 0);
  // A cell outside the recorded array changes nothing (and does not crash).
  const DeviceStatus before = s;
  mirror_action(s, Action::jam(7, 7));
  EXPECT_EQ(s.cell_jammed, before.cell_jammed);
  mirror_vent(s);
  EXPECT_EQ(s.pressure_pa, 0.0);
  EXPECT_EQ(std::count(s.cell_jammed.begin(), s.cell_jammed.end(), 1), 0);
  EXPECT_EQ(std::count(s.node_pinned.begin(), s.node_pinned.end(), 1), 0);
}

}  // namespace
}  // namespace hj::device
