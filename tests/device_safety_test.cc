// The device's own safety path (PROTOCOL.md, "Vent and watchdog"): a vent
// overtakes held commands, the emulator vents by itself on silence and on a
// closed connection, and the link's halt refuses every later action unsent.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <string>

#include "device/asio_device_link.h"
#include "device/make_device_link.h"
#include "device_test_support.h"
#include "expect_error.h"

namespace hj::device {
namespace {

using namespace std::chrono_literals;
using testing_support::EmulatedDevice;
using testing_support::eventually;

// A protocol connection by hand, each read bounded (10 s) so a test fails
// instead of hanging.
class LineClient {
 public:
  explicit LineClient(unsigned short port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval limit{10, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
    EXPECT_EQ(::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  }
  ~LineClient() { close(); }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  void send(const std::string& line) {
    const std::string bytes = line + "\n";
    EXPECT_EQ(::write(fd_, bytes.data(), bytes.size()), ssize_t(bytes.size()));
  }
  // The next line, or "" when none came within the bound.
  std::string line() {
    while (true) {
      if (const auto end = buffer_.find('\n'); end != std::string::npos) {
        std::string out = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        return out;
      }
      char chunk[4096];
      const ssize_t n = ::read(fd_, chunk, sizeof chunk);
      if (n <= 0) return "";
      buffer_.append(chunk, size_t(n));
    }
  }
  // The reply to request `id`, skipping others.
  std::string reply_to(int id) {
    const std::string ok = "ok " + std::to_string(id), err = "err " + std::to_string(id) + " ";
    for (std::string l = line(); !l.empty(); l = line())
      if (l == ok || l.rfind(ok + " ", 0) == 0 || l.rfind(err, 0) == 0) return l;
    return "";
  }

 private:
  int fd_ = -1;
  std::string buffer_;
};

EmulatorServerOptions with_watchdog(std::chrono::milliseconds watchdog) {
  EmulatorServerOptions o;
  o.watchdog = watchdog;
  return o;
}

std::string pressure_of(LineClient& client, int id) {
  client.send(std::to_string(id) + " status");
  const std::string status = client.reply_to(id);
  return status.substr(0, status.find(' ', status.find("pressure_pa=")));
}

TEST(DeviceSafety, AVentOvertakesHeldCommandsWhichAreNotCarriedOut) {
  EmulatedDevice device;
  LineClient client(device.server.port());
  client.send("1 set_pressure 500");
  EXPECT_EQ(client.reply_to(1), "ok 1");
  // A controller busy for 60 s: the vent must not wait for it.
  client.send("2 fault stall 60000");
  EXPECT_EQ(client.reply_to(2), "ok 2");
  client.send("3 set_pressure 900");
  client.send("4 vent");
  const std::string overtaken = client.line();
  EXPECT_EQ(overtaken.rfind("err 3 cancelled", 0), 0u) << overtaken;
  EXPECT_EQ(client.line(), "ok 4");
  ASSERT_EQ(device.server.vents().size(), 1u);
  EXPECT_EQ(device.server.vents()[0].why, "vent");
}

TEST(DeviceSafety, ARefusedActionIsNotCarriedOutAndTheNextOnesAre) {
  EmulatedDevice device;
  LineClient client(device.server.port());
  client.send("1 fault refuse 2");
  EXPECT_EQ(client.reply_to(1), "ok 1");
  client.send("2 set_pressure 500");
  EXPECT_EQ(client.reply_to(2), "ok 2");
  client.send("3 set_pressure 900");
  const std::string refused = client.reply_to(3);
  EXPECT_EQ(refused.rfind("err 3 failed set_pressure 900: refused", 0), 0u) << refused;
  EXPECT_EQ(pressure_of(client, 4), "ok 4 pressure_pa=500") << "the state is as before the refused action";
  client.send("5 set_pressure 900");
  EXPECT_EQ(client.reply_to(5), "ok 5") << "refused once";
}

TEST(DeviceSafety, TheEmulatorVentsByItselfWhenTheServerFallsSilent) {
  EmulatedDevice device(with_watchdog(300ms));
  LineClient client(device.server.port());
  client.send("1 set_pressure 800");
  ASSERT_EQ(client.reply_to(1), "ok 1");
  EXPECT_EQ(pressure_of(client, 2), "ok 2 pressure_pa=800");
  // Silence: no ping, no command.
  ASSERT_TRUE(eventually([&] { return !device.server.vents().empty(); }, 5000ms));
  const VentRecord vent = device.server.vents().front();
  EXPECT_EQ(vent.why, "watchdog: nothing heard for 300 ms");
  EXPECT_EQ(pressure_of(client, 3), "ok 3 pressure_pa=0");
}

TEST(DeviceSafety, AClosedConnectionCountsAsSilence) {
  EmulatedDevice device;
  {
    LineClient client(device.server.port());
    client.send("1 jam 0 1");
    ASSERT_EQ(client.reply_to(1), "ok 1");
  }
  ASSERT_TRUE(eventually([&] { return !device.server.vents().empty(); }, 5000ms));
  EXPECT_EQ(device.server.vents().front().why, "connection closed");
  LineClient next(device.server.port());
  next.send("2 status");
  const std::string status = next.reply_to(2);
  EXPECT_NE(status.find("pressure_pa=0 jammed=000000000000 "), std::string::npos) << status;
}

TEST(DeviceSafety, AnIdleArrayAtRestIsNotVentedOverAndOver) {
  EmulatedDevice device(with_watchdog(100ms));
  LineClient client(device.server.port());
  client.send("1 vent");
  ASSERT_EQ(client.reply_to(1), "ok 1");
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(device.server.vents().size(), 1u);
}

TEST(DeviceSafety, AHaltRefusesEveryLaterActionUnsentUntilReleased) {
  EmulatedDevice device;
  const auto link = make_device_link(device.endpoint());
  link->start();
  ASSERT_TRUE(eventually([&] { return link->connected(); }, 20000ms));
  link->execute(Action::set_pressure(400.0), 20s);
  link->halt_and_vent(20s);
  const std::size_t received = device.server.actions_received().size();
  testing_support::expect_error<DeviceError>([&] { link->execute(Action::jam(0, 1), 20s); },
                                             {"\"jam 0 1\" not sent: the device is halted by an emergency stop"});
  EXPECT_EQ(device.server.actions_received().size(), received);
  EXPECT_EQ(link->status().pressure_pa, 0.0);
  link->release_halt();
  link->execute(Action::jam(0, 1), 20s);
  EXPECT_EQ(device.server.actions_received().size(), received + 1);
  link->stop();
}

TEST(DeviceSafety, WatchdogOptionIsBoundedByTheProtocol) {
  Emulator emulator(testing_support::emulator_config_3x4());
  testing_support::expect_error<std::invalid_argument>(
      [&] { EmulatorServer(emulator, with_watchdog(6000ms)); }, {"emulator watchdog of 6000 ms: must be within 10..5000 ms"});
}

}  // namespace
}  // namespace hj::device
