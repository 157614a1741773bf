// End-to-end test support: the real hapticjam-server and
// hapticjam-device-emulator started as processes on loopback ports (port 0,
// read back from what they print), the `hapticjam` CLI run as a subprocess,
// and a raw line connection to the emulator to make it misbehave on cue.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hj::testing_support {

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A child process with stdout and stderr in files; SIGKILLed if still running
// when destroyed.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::filesystem::path& out, const std::filesystem::path& err)
      : out_(out), err_(err) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> copy = argv;
    std::vector<char*> args;
    for (auto& a : copy) args.push_back(a.data());
    args.push_back(nullptr);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
  }
  ~Process() {
    if (pid_ > 0) signal_and_wait(SIGKILL);
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }
  bool running() const { return pid_ > 0 && waitpid(pid_, nullptr, WNOHANG) == 0; }
  std::string out() const { return read_file(out_); }
  std::string err() const { return read_file(err_); }

  // Sends `sig` and reaps the process; its exit code, or -signal if killed.
  int signal_and_wait(int sig) {
    if (pid_ <= 0) return exit_code_;
    kill(pid_, sig);
    return wait();
  }
  int wait() {
    if (pid_ <= 0) return exit_code_;
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
    return exit_code_;
  }

  // Waits (up to `seconds`, a bound against hanging) for `pattern` in stdout
  // and returns its first group.
  std::string await_output(const std::string& pattern, double seconds = 30) const {
    const std::regex re(pattern);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      std::smatch m;
      const std::string text = out();
      if (std::regex_search(text, m, re)) return m.size() > 1 ? m[1].str() : m[0].str();
      if (!running()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    throw std::runtime_error("no \"" + pattern + "\" from " + out_.string() + ": " + out() + err());
  }

 private:
  std::filesystem::path out_, err_;
  pid_t pid_ = -1;
  int exit_code_ = -1;
};

// hapticjam-device-emulator on 127.0.0.1, a free port.
struct Emulator {
  Emulator(const std::filesystem::path& dir, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {HJ_EMULATOR_PATH, "--listen", "127.0.0.1:0"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    process = std::make_unique<Process>(argv, dir / "emulator.out", dir / "emulator.err");
    port = std::stoi(process->await_output(R"(listening on 127\.0\.0\.1:(\d+))"));
  }
  std::string endpoint() const { return "127.0.0.1:" + std::to_string(port); }
  std::unique_ptr<Process> process;
  int port = 0;
};

// hapticjam-server on 127.0.0.1, a free port, its queue in `db`.
struct Server {
  Server(const std::filesystem::path& dir, const std::filesystem::path& db, std::vector<std::string> extra = {},
         const std::string& label = "server") {
    std::vector<std::string> argv = {HJ_SERVER_PATH, "--listen", "127.0.0.1:0", "--db", db.string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    process = std::make_unique<Process>(argv, dir / (label + ".out"), dir / (label + ".err"));
    port = std::stoi(process->await_output(R"(listening on port (\d+))"));
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port); }
  std::unique_ptr<Process> process;
  int port = 0;
};

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `hapticjam ARGS...`, its output captured in `dir`.
inline CliResult run_cli(const std::vector<std::string>& args, const std::filesystem::path& dir) {
  static int counter = 0;
  const std::string tag = std::to_string(++counter);
  const auto out = dir / ("cli" + tag + ".out"), err = dir / ("cli" + tag + ".err");
  std::string command = shell_quote(HJ_CLI_PATH);
  for (const auto& a : args) command.append(" ").append(shell_quote(a));
  command.append(" >").append(shell_quote(out.string())).append(" 2>").append(shell_quote(err.string()));
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(out), read_file(err)};
}

// A raw protocol connection to the emulator (src/device/PROTOCOL.md), for faults.
// While it waits for a reply it sends the link's heartbeat (a `ping` every
// 200 ms), so a long settle is not taken for silence by the watchdog.
class EmulatorLine {
 public:
  explicit EmulatorLine(int port) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
      throw std::runtime_error("cannot connect to the emulator");
  }
  ~EmulatorLine() { close(fd_); }
  // Sends "ID COMMAND" and returns the reply line to that id.
  std::string request(const std::string& command) {
    const std::string id = send_line(command);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(10);
    while (true) {
      const auto nl = buffer_.find('\n');
      if (nl != std::string::npos) {
        std::string reply = buffer_.substr(0, nl);
        buffer_.erase(0, nl + 1);
        std::istringstream words(reply);
        std::string status, reply_id;
        words >> status >> reply_id;
        if (reply_id == id) return reply;
        continue;
      }
      if (std::chrono::steady_clock::now() > give_up) throw std::runtime_error("no reply to " + command);
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 200) == 0) {
        send_line("ping");
        continue;
      }
      char chunk[4096];
      const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
      if (n <= 0) throw std::runtime_error("emulator closed the line");
      buffer_.append(chunk, size_t(n));
    }
  }

 private:
  std::string send_line(const std::string& command) {
    const std::string id = std::to_string(++id_);
    const std::string line = id + " " + command + "\n";
    if (::send(fd_, line.data(), line.size(), MSG_NOSIGNAL) != ssize_t(line.size()))
      throw std::runtime_error("emulator write failed");
    return id;
  }

  int fd_ = -1;
  int id_ = 0;
  std::string buffer_;
};

// Hang bounds grow by HJ_TEST_TIME_SCALE (default 1): the sanitizer build
// (scripts/sanitize.sh) runs several times slower.
inline double time_scale() {
  const char* scale = std::getenv("HJ_TEST_TIME_SCALE");
  return scale ? std::max(1.0, std::atof(scale)) : 1.0;
}

// Polls `done` every 20 ms for up to `seconds` x time_scale() (a bound
// against hanging, not a timing assertion); true once it holds.
template <typename F>
bool wait_until(F done, double seconds = 30.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds * time_scale());
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return done();
}

}  // namespace hj::testing_support
