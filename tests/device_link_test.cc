// The Asio device link against the in-process emulator on loopback: the
// surface it captures is the simulator's, status and vent tell and make the
// true state, and every failure (refusal, stall, drop, mute device, no
// device) comes back as the right DeviceError without hanging.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "calib/rasterize.h"
#include "device/asio_device_link.h"
#include "device/make_device_link.h"
#include "device_test_support.h"
#include "expect_error.h"

namespace hj::device {
namespace {

using namespace std::chrono_literals;
using testing_support::ConnectionEvents;
using testing_support::EmulatedDevice;
using testing_support::eventually;
using testing_support::expect_error;

constexpr auto kLong = 20s;  // a bound for commands that must succeed

LinkOptions fast_options() {
  LinkOptions o;
  o.connect_timeout = 2000ms;
  o.heartbeat_interval = 50ms;
  o.heartbeat_timeout = 1000ms;
  o.backoff_initial = 10ms;
  o.backoff_max = 100ms;
  return o;
}

// NaN where `expected` is NaN, the same double elsewhere.
void expect_same_frame(const Eigen::MatrixXd& got, const Eigen::MatrixXd& expected) {
  ASSERT_EQ(got.rows(), expected.rows());
  ASSERT_EQ(got.cols(), expected.cols());
  int seen = 0;
  for (Eigen::Index i = 0; i < got.size(); ++i) {
    const double g = got.data()[i], e = expected.data()[i];
    if (std::isnan(e)) {
      EXPECT_TRUE(std::isnan(g)) << "sample " << i;
    } else {
      EXPECT_EQ(g, e) << "sample " << i;
      ++seen;
    }
  }
  EXPECT_GT(seen, 0);
}

DeviceError::Kind kind_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const DeviceError& e) {
    return e.kind();
  }
  ADD_FAILURE() << "no DeviceError";
  return DeviceError::Kind::kRefused;
}

class DeviceLinkTest : public ::testing::Test {
 protected:
  void connect(EmulatedDevice& device, LinkOptions options = fast_options()) {
    link = std::make_unique<AsioDeviceLink>(parse_endpoint(device.endpoint()), options);
    link->on_connection_change(events.callback());
    link->start();
    ASSERT_TRUE(events.reach(1));
    ASSERT_TRUE(link->connected());
  }
  ConnectionEvents events;
  std::unique_ptr<AsioDeviceLink> link;
};

TEST_F(DeviceLinkTest, EachActionThenCaptureGivesTheSimulatorsSurface) {
  EmulatedDevice device;
  connect(device);
  const auto config = testing_support::emulator_config_3x4();
  Simulator direct(config.geometry, config.params);
  const std::vector<Action> actions = {Action::set_pressure(301.0), Action::jam(0, 3),     Action::pin(1, 2),
                                       Action::set_pressure(1500.0), Action::unpin(1, 2), Action::unjam(0, 3)};
  for (const Action& a : actions) {
    SCOPED_TRACE(a.describe());
    link->execute(a, kLong);
    direct.apply(a);
    const Capture c = link->capture(kLong);
    EXPECT_EQ(c.grid.nx, 77);
    EXPECT_EQ(c.grid.ny, 58);
    expect_same_frame(c.heights_mm, rasterize_top_view(direct.mesh(), direct.state().x, config.camera.grid));
  }
  ASSERT_TRUE(link->status().last_capture.has_value());
  EXPECT_EQ(link->status().last_capture->grid.nx, 77);
}

TEST_F(DeviceLinkTest, StatusReportsTheDevicesState) {
  EmulatedDevice device;
  connect(device);
  DeviceStatus s = link->status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.endpoint, device.endpoint());
  EXPECT_EQ(s.rows, 3);
  EXPECT_EQ(s.cols, 4);
  EXPECT_EQ(s.max_pressure_pa, 3450.0);
  EXPECT_EQ(s.pressure_pa, 0.0);
  link->execute(Action::set_pressure(500.0), kLong);
  link->execute(Action::jam(2, 1), kLong);
  link->execute(Action::pin(2, 3), kLong);
  for (const DeviceStatus& st : {link->status(), link->query_status(kLong)}) {
    EXPECT_EQ(st.pressure_pa, 500.0);
    ASSERT_EQ(st.cell_jammed.size(), 12u);
    ASSERT_EQ(st.node_pinned.size(), 20u);  // (3 + 1) x (4 + 1) corners
    for (int i = 0; i < 12; ++i) EXPECT_EQ(st.cell_jammed[i] != 0, i == 2 * 4 + 1) << "cell " << i;
    for (int i = 0; i < 20; ++i) EXPECT_EQ(st.node_pinned[i] != 0, i == 2 * 5 + 3) << "node " << i;
  }
  // The device agrees, not only the link's mirror.
  const DeviceState& truth = device.emulator.simulator().state();
  EXPECT_EQ(truth.pressure_pa, 500.0);
  EXPECT_TRUE(truth.jammed(device.emulator.simulator().mesh(), 2, 1));
  EXPECT_TRUE(truth.pinned(device.emulator.simulator().mesh(), 2, 3));
}

TEST_F(DeviceLinkTest, VentLeavesTheDeviceSafeAtTheRestSurface) {
  EmulatedDevice device;
  connect(device);
  const Eigen::MatrixXd rest = link->capture(kLong).heights_mm;
  for (const Action& a : {Action::set_pressure(800.0), Action::jam(0, 0), Action::jam(1, 2), Action::pin(1, 1),
                          Action::pin(2, 2)})
    link->execute(a, kLong);
  link->vent(kLong);
  const DeviceStatus s = link->query_status(kLong);
  EXPECT_EQ(s.pressure_pa, 0.0);
  for (const char j : s.cell_jammed) EXPECT_EQ(j, 0);
  for (const char p : s.node_pinned) EXPECT_EQ(p, 0);
  // Nothing holds the membrane any more: it sags back to its rest shape.
  const Eigen::MatrixXd after = link->capture(kLong).heights_mm;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < rest.size(); ++i)
    if (!std::isnan(rest.data()[i])) worst = std::max(worst, std::abs(after.data()[i] - rest.data()[i]));
  EXPECT_LT(worst, 1e-3) << "mm";
}

TEST_F(DeviceLinkTest, UnsafePressureAndBadIndicesAreRefusedNamingTheLimit) {
  EmulatedDevice device;
  connect(device);
  expect_error<DeviceError>([&] { link->execute(Action::set_pressure(5000.0), kLong); },
                            {"set_pressure 5000", "unsafe", "5 kPa", "[0, 3.45] kPa"});
  EXPECT_EQ(kind_of([&] { link->execute(Action::set_pressure(-1.0), kLong); }), DeviceError::Kind::kRefused);
  expect_error<DeviceError>([&] { link->execute(Action::jam(3, 0), kLong); }, {"out_of_range", "cell [3, 0]"});
  expect_error<DeviceError>([&] { link->execute(Action::pin(0, 1), kLong); }, {"node [0, 1]", "a in 1..2"});
  EXPECT_NE(link->status().last_error.find("node [0, 1]"), std::string::npos);
  // Refusals change nothing and the link stays up.
  EXPECT_EQ(link->query_status(kLong).pressure_pa, 0.0);
  EXPECT_TRUE(link->connected());
  EXPECT_EQ(events.events(), std::vector<bool>{true});
}

TEST_F(DeviceLinkTest, AStalledDeviceTimesOutTheCommandAndTheLinkRecovers) {
  EmulatedDevice device;
  connect(device);
  device.server.stall(1500ms);  // commands held; heartbeats still answered
  expect_error<DeviceError>([&] { link->execute(Action::set_pressure(100.0), 100ms); },
                            {"set_pressure 100", "no reply within 100 ms"});
  EXPECT_EQ(kind_of([&] { link->capture(100ms); }), DeviceError::Kind::kTimeout);
  // Still connected; after the stall the device answers again.
  EXPECT_TRUE(link->connected());
  link->execute(Action::set_pressure(200.0), kLong);
  EXPECT_EQ(link->query_status(kLong).pressure_pa, 200.0);
}

// Replies that race their command's timeout: each command either returns
// or times out, and the late replies confuse no later command.
TEST_F(DeviceLinkTest, RepliesRacingTheirTimeoutAreEitherTakenOrDropped) {
  EmulatedDevice device;
  connect(device);
  int answered = 0, timed_out = 0;
  for (int i = 0; i < 300; ++i) {
    try {
      link->ping(std::chrono::milliseconds(i % 2));
      ++answered;
    } catch (const DeviceError& e) {
      ASSERT_EQ(e.kind(), DeviceError::Kind::kTimeout) << e.what();
      ++timed_out;
    }
  }
  EXPECT_EQ(answered + timed_out, 300);
  link->execute(Action::set_pressure(700.0), kLong);
  EXPECT_EQ(link->query_status(kLong).pressure_pa, 700.0);
  EXPECT_TRUE(link->connected());
}

TEST_F(DeviceLinkTest, ADropDuringACommandFailsItThenTheLinkReconnects) {
  EmulatedDevice device;
  connect(device);
  // "fault drop": the device closes the connection instead of answering.
  EXPECT_EQ(kind_of([&] { link->send_raw("fault drop", kLong); }), DeviceError::Kind::kDisconnected);
  ASSERT_TRUE(events.reach(3));  // down, then up again after the backoff
  EXPECT_EQ(events.events(), (std::vector<bool>{true, false, true}));
  link->execute(Action::jam(1, 1), kLong);
  EXPECT_EQ(link->query_status(kLong).cell_jammed[1 * 4 + 1], 1);
}

TEST_F(DeviceLinkTest, ADropMidJobFailsThatActionAndNothingIsResent) {
  EmulatedDevice device({"127.0.0.1", 0, /*drop_after=*/2});
  connect(device);
  link->execute(Action::set_pressure(300.0), kLong);
  link->execute(Action::jam(0, 0), kLong);
  expect_error<DeviceError>([&] { link->execute(Action::pin(1, 1), kLong); },
                            {"dropped during", "pin 1 1", device.endpoint()});
  ASSERT_TRUE(events.reach(3));
  EXPECT_EQ(events.events(), (std::vector<bool>{true, false, true}));
  // The dropped pin never reached the device and the link did not repeat it;
  // the device vented itself when the connection closed.
  const auto received = device.server.actions_received();
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[1].line.substr(received[1].line.find(' ') + 1), "jam 0 0");
  ASSERT_EQ(device.server.vents().size(), 1u);
  EXPECT_EQ(device.server.vents()[0].why, "connection closed");
  const DeviceStatus s = link->query_status(kLong);
  EXPECT_EQ(s.node_pinned[1 * 5 + 1], 0);
  EXPECT_EQ(s.cell_jammed[0], 0);
  EXPECT_EQ(s.pressure_pa, 0.0);
}

TEST_F(DeviceLinkTest, AMuteDeviceIsFoundByTheHeartbeatAndReconnected) {
  EmulatedDevice device;
  LinkOptions o = fast_options();
  o.heartbeat_timeout = 300ms;
  o.connect_timeout = 300ms;
  connect(device, o);
  device.server.mute(2000ms);  // not even pings are answered
  ASSERT_TRUE(events.reach(2));
  EXPECT_EQ(events.events()[1], false);
  EXPECT_EQ(kind_of([&] { link->ping(kLong); }), DeviceError::Kind::kDisconnected);
  ASSERT_TRUE(events.reach(3));
  EXPECT_EQ(events.events()[2], true);
  link->ping(kLong);
}

TEST_F(DeviceLinkTest, WithoutADeviceCommandsFailAtOnceAndStopReturns) {
  unsigned short port = 0;
  {
    EmulatedDevice gone;  // a port that was free a moment ago
    port = gone.server.port();
  }
  auto down = make_device_link("127.0.0.1:" + std::to_string(port), fast_options());
  down->on_connection_change(events.callback());
  down->start();
  ASSERT_TRUE(eventually([&] { return !down->status().last_error.empty(); }));  // an attempt failed
  EXPECT_FALSE(down->connected());
  expect_error<DeviceError>([&] { down->execute(Action::set_pressure(100.0), kLong); },
                            {"is down", "not sent", "cannot connect"});
  EXPECT_EQ(kind_of([&] { down->vent(kLong); }), DeviceError::Kind::kDisconnected);
  EXPECT_FALSE(down->status().connected);
  down->stop();
  EXPECT_TRUE(events.events().empty());
}

TEST_F(DeviceLinkTest, StopFailsAWaitingCommand) {
  EmulatedDevice device;
  connect(device);
  device.server.stall(3000ms);
  std::thread stopper([&] {
    std::this_thread::sleep_for(100ms);
    link->stop();
  });
  EXPECT_EQ(kind_of([&] { link->capture(kLong); }), DeviceError::Kind::kDisconnected);
  stopper.join();
  EXPECT_FALSE(link->connected());
}

TEST_F(DeviceLinkTest, ACallbackMayVentOnReconnect) {
  EmulatedDevice device({"127.0.0.1", 0, /*drop_after=*/2});
  auto link = std::make_unique<AsioDeviceLink>(parse_endpoint(device.endpoint()), fast_options());
  std::atomic<int> vented{0};
  AsioDeviceLink* raw = link.get();
  link->on_connection_change([&](bool up) {
    // What the server does after a fault: make the device safe first.
    if (up) {
      raw->vent(kLong);
      ++vented;
    }
  });
  link->start();
  ASSERT_TRUE(eventually([&] { return vented == 1; }));
  link->execute(Action::set_pressure(900.0), kLong);
  EXPECT_EQ(kind_of([&] { link->execute(Action::jam(0, 0), kLong); }), DeviceError::Kind::kDisconnected);
  ASSERT_TRUE(eventually([&] { return vented == 2; }));
  EXPECT_EQ(link->query_status(kLong).pressure_pa, 0.0);
  link->stop();
}

TEST_F(DeviceLinkTest, StopThenStartConnectsAgain) {
  EmulatedDevice device;
  connect(device);
  link->stop();
  EXPECT_FALSE(link->connected());
  EXPECT_EQ(kind_of([&] { link->ping(kLong); }), DeviceError::Kind::kDisconnected);
  link->start();
  ASSERT_TRUE(events.reach(2));
  EXPECT_EQ(events.events(), (std::vector<bool>{true, true}));  // no callback from stop()
  link->ping(kLong);
}

// A "device" on a plain socket that answers the first line of every
// connection with `reply`, then hangs up.
class ScriptedDevice {
 public:
  explicit ScriptedDevice(std::string reply) : reply_(std::move(reply)) {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof address;
    if (bind(listener_, reinterpret_cast<sockaddr*>(&address), size) != 0 || listen(listener_, 8) != 0 ||
        getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &size) != 0)
      throw std::runtime_error("scripted device cannot listen");
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] {
      while (true) {
        const int c = accept(listener_, nullptr, nullptr);
        if (c < 0 || stop_) {
          if (c >= 0) close(c);
          return;
        }
        ++connections;
        char buffer[256];
        const ssize_t n = read(c, buffer, sizeof buffer);
        if (n > 0) {
          // "ID" in the script becomes the id of the request (the hello).
          std::string reply = reply_;
          const std::string id(buffer, std::find(buffer, buffer + n, ' '));
          if (const auto at = reply.find("ID"); at != std::string::npos) reply.replace(at, 2, id);
          (void)!write(c, reply.data(), reply.size());
        }
        close(c);
      }
    });
  }
  ~ScriptedDevice() {
    stop_ = true;
    shutdown(listener_, SHUT_RDWR);  // wakes accept()
    thread_.join();
    close(listener_);
  }
  std::string endpoint() const { return "127.0.0.1:" + std::to_string(port_); }
  std::atomic<int> connections{0};

 private:
  std::string reply_;
  int listener_ = -1;
  unsigned short port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST_F(DeviceLinkTest, GarbageFromTheDeviceIsAFailedConnectionNotACrash) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"garbage\n", "bad reply: reply \"garbage\" starts with neither ok nor err"},
      {"ok ID protocol=1 rows=x\n", "bad reply: hello: rows=\"x\" is not a whole number"},
      {"ok ID protocol=9 rows=3 cols=4 cell_mm=38 max_pressure_pa=3450 grid=77,58,0,0,2,2\n",
       "device speaks protocol 9, this link 1"},
      {std::string(5000, '\x01') + "\n", "starts with neither ok nor err"},
  };
  for (const auto& [reply, error] : cases) {
    SCOPED_TRACE(error);
    ScriptedDevice liar(reply);
    auto l = make_device_link(liar.endpoint(), fast_options());
    l->start();
    ASSERT_TRUE(eventually([&] { return liar.connections >= 2; }));  // refused, then tried again
    EXPECT_FALSE(l->connected());
    EXPECT_NE(l->status().last_error.find(error), std::string::npos) << l->status().last_error;
    l->stop();
  }
}

}  // namespace
}  // namespace hj::device
