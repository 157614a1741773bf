// The device link over a serial port: a pseudo-terminal stands in for the
// cable, its far end relayed to the in-process emulator's TCP port.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "device/asio_device_link.h"
#include "device_test_support.h"
#include "expect_error.h"

namespace hj::device {
namespace {

using namespace std::chrono_literals;

// Copies bytes between a pseudo-terminal's master side and a TCP
// connection to `port` until destroyed.
class PtyRelay {
 public:
  explicit PtyRelay(unsigned short port) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) throw std::runtime_error("no pty");
    slave_path_ = ptsname(master_);
    // Held open so the master never sees a hang-up between opens; raw, so
    // nothing is echoed or translated before the link sets the port up.
    slave_ = open(slave_path_.c_str(), O_RDWR | O_NOCTTY);
    termios raw{};
    tcgetattr(slave_, &raw);
    cfmakeraw(&raw);
    tcsetattr(slave_, TCSANOW, &raw);
    socket_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(socket_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0)
      throw std::runtime_error("relay cannot connect");
    thread_ = std::thread([this] { relay(); });
  }
  ~PtyRelay() {
    stop_ = true;
    thread_.join();
    close(socket_);
    close(slave_);
    close(master_);
  }
  const std::string& path() const { return slave_path_; }

 private:
  void relay() {
    char buffer[4096];
    while (!stop_) {
      pollfd fds[2] = {{master_, POLLIN, 0}, {socket_, POLLIN, 0}};
      if (poll(fds, 2, 20) <= 0) continue;
      for (int i = 0; i < 2; ++i) {
        if (!(fds[i].revents & POLLIN)) continue;
        const ssize_t n = read(fds[i].fd, buffer, sizeof buffer);
        if (n <= 0) return;
        for (ssize_t done = 0; done < n;) {
          const ssize_t w = write(i == 0 ? socket_ : master_, buffer + done, n - done);
          if (w <= 0) return;
          done += w;
        }
      }
    }
  }

  int master_ = -1, slave_ = -1, socket_ = -1;
  std::string slave_path_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST(DeviceSerialLink, SpeaksTheProtocolOverASerialPort) {
  const int probe = posix_openpt(O_RDWR | O_NOCTTY);
  if (probe < 0) GTEST_SKIP() << "this machine offers no pseudo-terminals (/dev/ptmx)";
  close(probe);
  testing_support::EmulatedDevice device;
  PtyRelay cable(device.server.port());
  LinkOptions options;
  options.baud_rate = 9600;
  AsioDeviceLink link(parse_endpoint(cable.path()), options);
  testing_support::ConnectionEvents events;
  link.on_connection_change(events.callback());
  link.start();
  ASSERT_TRUE(events.reach(1)) << link.status().last_error;
  EXPECT_EQ(link.status().endpoint, cable.path());
  link.execute(Action::jam(1, 2), 20s);
  const Capture c = link.capture(20s);  // about 80 kB through the pty
  EXPECT_EQ(c.heights_mm.rows(), 58);
  EXPECT_EQ(c.heights_mm.cols(), 77);
  EXPECT_EQ(link.query_status(20s).cell_jammed[1 * 4 + 2], 1);
  link.stop();
}

TEST(DeviceSerialLink, AMissingPortIsReportedAndRetried) {
  LinkOptions options;
  options.backoff_initial = 10ms;
  options.backoff_max = 50ms;
  AsioDeviceLink link(parse_endpoint("/dev/hapticjam-no-such-tty"), options);
  link.start();
  ASSERT_TRUE(testing_support::eventually([&] { return !link.status().last_error.empty(); }));
  EXPECT_NE(link.status().last_error.find("cannot open"), std::string::npos) << link.status().last_error;
  testing_support::expect_error<DeviceError>([&] { link.ping(1s); }, {"/dev/hapticjam-no-such-tty", "is down"});
  link.stop();
}

}  // namespace
}  // namespace hj::device
