// The device line protocol (src/device/PROTOCOL.md) as pure functions: one
// request or reply per line, formatted and parsed here and nowhere else, so
// the link, the emulator and the tests agree on every byte. Parsing never
// trusts its input: anything malformed is a ProtocolError naming what is
// wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "device/device_link.h"
#include "model/action.h"

namespace hj::device::protocol {

constexpr int kVersion = 1;
// A request line (without its "\n") is at most this long.
constexpr std::size_t kMaxRequestBytes = 1024;
// A reply line is at most this long (a capture of about a million samples).
constexpr std::size_t kMaxReplyBytes = 32u << 20;
// A capture holds at most this many samples.
constexpr long kMaxCaptureSamples = 2'000'000;

// The CODE of an "err" reply.
enum class ErrorCode { kMalformed, kUnknownCommand, kTooLong, kOutOfRange, kUnsafe, kFailed, kCancelled };
const char* error_code_name(ErrorCode code);

// A line that is not a valid request or reply. `id` is the request id when
// it could be read (so the error can be answered to it), else 0.
class ProtocolError : public std::runtime_error {
 public:
  ProtocolError(ErrorCode code, std::uint64_t id, const std::string& what)
      : std::runtime_error(what), code_(code), id_(id) {}
  ErrorCode code() const { return code_; }
  std::uint64_t id() const { return id_; }

 private:
  ErrorCode code_;
  std::uint64_t id_;
};

// kTruth is the emulator's test hook: the true surface, not what its camera
// reports (PROTOCOL.md, "The true surface").
enum class Command { kHello, kPing, kStatus, kCapture, kVent, kAction, kFault, kTruth };

// Test hooks of the emulator (PROTOCOL.md, "Faults").
struct Fault {
  enum class Kind { kDrop, kStall, kMute, kRefuse };
  Kind kind = Kind::kDrop;
  int ms = 0;       // kStall, kMute
  int actions = 0;  // kRefuse: the action this many from now is refused
};

struct Request {
  std::uint64_t id = 0;  // >= 1
  Command command = Command::kPing;
  Action action;  // kAction
  Fault fault;    // kFault
};

// "7 jam 0 3" (no line end). Pressures are written exactly (shortest text
// that reads back as the same double).
std::string format_request(const Request& request);
// Parses one line without its line end.
// @throws ProtocolError: kMalformed (bad id, missing or extra arguments, a
//         number that is not one), kUnknownCommand, kTooLong.
Request parse_request(std::string_view line);

struct Reply {
  std::uint64_t id = 0;  // 0: the request it answers could not be read
  bool ok = false;
  std::string code;      // err only: the CODE word
  std::string text;      // ok: the payload (may be empty); err: the message
};

// "ok 7" / "ok 7 PAYLOAD".
std::string format_ok(std::uint64_t id, std::string_view payload = {});
// "err 7 CODE MESSAGE"; line ends in the message become spaces.
std::string format_err(std::uint64_t id, ErrorCode code, std::string_view message);
// @throws ProtocolError(kMalformed) naming what is wrong.
Reply parse_reply(std::string_view line);

// What "hello" answers: the protocol version and the array.
struct Hello {
  int protocol = kVersion;
  int rows = 0, cols = 0;
  double cell_mm = 0.0;
  double max_pressure_pa = 0.0;
  CaptureGrid grid;
};
std::string format_hello(const Hello& hello);
// Unknown keys are skipped (newer devices may add some).
// @throws ProtocolError(kMalformed) naming a missing or bad key.
Hello parse_hello(std::string_view payload);

// What "status" answers: pressure, jammed cells (rows*cols) and pinned nodes
// ((rows+1)*(cols+1), the array's corners included), row-major, as '0'/'1'.
struct StatusPayload {
  double pressure_pa = 0.0;
  std::vector<char> cell_jammed;
  std::vector<char> node_pinned;
};
std::string format_status(const StatusPayload& status);
// @throws ProtocolError(kMalformed) if a key is missing or a bit string has
//         the wrong length for a rows x cols array.
StatusPayload parse_status(std::string_view payload, int rows, int cols);

// What "capture" answers: "frame NX NY X0 Y0 DX DY v,v,...", ny rows of nx
// heights in mm, row-major, "nan" for a sample not seen; exact doubles.
std::string format_capture(const Capture& capture);
// @throws ProtocolError(kMalformed) naming the field or sample that is wrong.
Capture parse_capture(std::string_view payload);

// Shortest text that reads back as exactly `value` ("nan" for NaN).
std::string format_double(double value);

}  // namespace hj::device::protocol
