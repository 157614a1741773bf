#include "device/protocol.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace hj::device::protocol {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] void malformed(std::uint64_t id, const std::string& what) {
  throw ProtocolError(ErrorCode::kMalformed, id, what);
}

// At most 40 characters of untrusted text, control bytes shown as '?', for
// quoting in a message.
std::string quote(std::string_view text) {
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    out += (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
  }
  if (text.size() > 40) out += "...";
  return out + "\"";
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

std::optional<std::uint64_t> read_id(std::string_view word) {
  std::uint64_t id = 0;
  if (word.empty() || word.front() < '0' || word.front() > '9') return std::nullopt;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), id);
  if (ec != std::errc() || end != word.data() + word.size() || id == 0) return std::nullopt;
  return id;
}

std::optional<long long> read_integer(std::string_view word) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (word.empty() || ec != std::errc() || end != word.data() + word.size()) return std::nullopt;
  return value;
}

// A finite decimal number, or NaN for "nan" when allowed.
std::optional<double> read_double(std::string_view word, bool allow_nan) {
  if (word.size() > 1 && word.front() == '+') word.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (word.empty() || ec != std::errc() || end != word.data() + word.size()) return std::nullopt;
  if (std::isnan(value)) return allow_nan ? std::optional<double>(kNaN) : std::nullopt;
  if (std::isinf(value)) return std::nullopt;
  return value;
}

int int_argument(std::uint64_t id, std::string_view word, const char* what, long long lo, long long hi) {
  const auto value = read_integer(word);
  if (!value) malformed(id, std::string(what) + " " + quote(word) + " is not a whole number");
  if (*value < lo || *value > hi)
    malformed(id, std::string(what) + " " + std::to_string(*value) + " is outside [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "]");
  return static_cast<int>(*value);
}

void expect_arguments(std::uint64_t id, const std::vector<std::string_view>& words, std::size_t count,
                      const char* usage) {
  const std::size_t given = words.size() - 2;
  if (given != count)
    malformed(id, std::string(words[1]) + " takes " + std::to_string(count) + " argument" + (count == 1 ? "" : "s") +
                      (count ? " (" + std::string(usage) + ")" : std::string()) + ", got " + std::to_string(given));
}

// Parses "key=value" words into a lookup.
std::optional<std::string_view> find_key(const std::vector<std::string_view>& words, std::string_view key) {
  for (const auto w : words) {
    const std::size_t eq = w.find('=');
    if (eq != std::string_view::npos && w.substr(0, eq) == key) return w.substr(eq + 1);
  }
  return std::nullopt;
}

std::string_view require_key(const std::vector<std::string_view>& words, std::string_view key, const char* where) {
  const auto value = find_key(words, key);
  if (!value) malformed(0, std::string(where) + ": missing " + std::string(key) + "=");
  return *value;
}

double key_double(const std::vector<std::string_view>& words, std::string_view key, const char* where) {
  const std::string_view text = require_key(words, key, where);
  const auto value = read_double(text, false);
  if (!value) malformed(0, std::string(where) + ": " + std::string(key) + "=" + quote(text) + " is not a number");
  return *value;
}

int key_int(const std::vector<std::string_view>& words, std::string_view key, const char* where, int lo, int hi) {
  const std::string_view text = require_key(words, key, where);
  const auto value = read_integer(text);
  if (!value || *value < lo || *value > hi)
    malformed(0, std::string(where) + ": " + std::string(key) + "=" + quote(text) + " is not a whole number in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(*value);
}

std::string bits(const std::vector<char>& flags) {
  std::string out;
  out.reserve(flags.size());
  for (const char f : flags) out += f ? '1' : '0';
  return out;
}

std::vector<char> read_bits(std::string_view text, std::size_t expected, const char* key) {
  if (text.size() != expected)
    malformed(0, std::string("status: ") + key + " has " + std::to_string(text.size()) + " flags, expected " +
                     std::to_string(expected));
  std::vector<char> flags(expected);
  for (std::size_t i = 0; i < expected; ++i) {
    if (text[i] != '0' && text[i] != '1')
      malformed(0, std::string("status: ") + key + " flag " + std::to_string(i) + " is not 0 or 1");
    flags[i] = text[i] == '1';
  }
  return flags;
}

// Grid fields "NX NY X0 Y0 DX DY" shared by hello (comma-separated) and
// capture (space-separated).
CaptureGrid read_grid(const std::vector<std::string_view>& fields, const char* where) {
  if (fields.size() != 6) malformed(0, std::string(where) + ": a grid needs 6 fields (nx ny x0 y0 dx dy)");
  CaptureGrid grid;
  const auto n = [&](std::string_view w, const char* name) {
    const auto v = read_integer(w);
    if (!v || *v < 1 || *v > kMaxCaptureSamples)
      malformed(0, std::string(where) + ": grid " + name + " " + quote(w) + " is not a whole number in [1, " +
                       std::to_string(kMaxCaptureSamples) + "]");
    return static_cast<int>(*v);
  };
  const auto x = [&](std::string_view w, const char* name, bool positive) {
    const auto v = read_double(w, false);
    if (!v || (positive && *v <= 0.0))
      malformed(0, std::string(where) + ": grid " + name + " " + quote(w) + " is not a " +
                       (positive ? "positive " : "") + "number");
    return *v;
  };
  grid.nx = n(fields[0], "nx");
  grid.ny = n(fields[1], "ny");
  if (static_cast<long>(grid.nx) * grid.ny > kMaxCaptureSamples)
    malformed(0, std::string(where) + ": grid of " + std::to_string(grid.nx) + " x " + std::to_string(grid.ny) +
                     " samples exceeds " + std::to_string(kMaxCaptureSamples));
  grid.x0_mm = x(fields[2], "x0", false);
  grid.y0_mm = x(fields[3], "y0", false);
  grid.dx_mm = x(fields[4], "dx", true);
  grid.dy_mm = x(fields[5], "dy", true);
  return grid;
}

std::vector<std::string_view> split_on(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  while (true) {
    const std::size_t end = text.find(sep);
    out.push_back(text.substr(0, end));
    if (end == std::string_view::npos) return out;
    text.remove_prefix(end + 1);
  }
}

std::string grid_text(const CaptureGrid& g, char sep) {
  std::string out = std::to_string(g.nx) + sep + std::to_string(g.ny);
  for (const double v : {g.x0_mm, g.y0_mm, g.dx_mm, g.dy_mm}) out += sep + format_double(v);
  return out;
}

}  // namespace

const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kMalformed: return "malformed";
    case ErrorCode::kUnknownCommand: return "unknown_command";
    case ErrorCode::kTooLong: return "too_long";
    case ErrorCode::kOutOfRange: return "out_of_range";
    case ErrorCode::kUnsafe: return "unsafe";
    case ErrorCode::kFailed: return "failed";
    case ErrorCode::kCancelled: return "cancelled";
  }
  return "failed";
}

std::string format_double(double value) {
  if (std::isnan(value)) return "nan";
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  if (ec != std::errc()) throw std::logic_error("format_double: buffer too small");
  return std::string(buffer, end);
}

std::string format_request(const Request& r) {
  std::string out = std::to_string(r.id) + ' ';
  switch (r.command) {
    case Command::kHello: return out + "hello";
    case Command::kPing: return out + "ping";
    case Command::kStatus: return out + "status";
    case Command::kCapture: return out + "capture";
    case Command::kVent: return out + "vent";
    case Command::kTruth: return out + "truth";
    case Command::kAction:
      out += r.action.op_name();
      if (r.action.op == Action::Op::kSetPressure) return out + ' ' + format_double(r.action.pressure_pa);
      return out + ' ' + std::to_string(r.action.a) + ' ' + std::to_string(r.action.b);
    case Command::kFault:
      switch (r.fault.kind) {
        case Fault::Kind::kDrop: return out + "fault drop";
        case Fault::Kind::kStall: return out + "fault stall " + std::to_string(r.fault.ms);
        case Fault::Kind::kMute: return out + "fault mute " + std::to_string(r.fault.ms);
        case Fault::Kind::kRefuse: return out + "fault refuse " + std::to_string(r.fault.actions);
      }
  }
  throw std::logic_error("format_request: unknown command");
}

Request parse_request(std::string_view line) {
  if (line.size() > kMaxRequestBytes)
    throw ProtocolError(ErrorCode::kTooLong, 0,
                        "line of " + std::to_string(line.size()) + " bytes exceeds " +
                            std::to_string(kMaxRequestBytes));
  const auto words = split_words(line);
  if (words.empty()) malformed(0, "empty line");
  const auto id = read_id(words[0]);
  if (!id) malformed(0, "request id " + quote(words[0]) + " is not a whole number >= 1");
  Request r;
  r.id = *id;
  if (words.size() < 2) malformed(r.id, "missing command after the request id");
  const std::string_view name = words[1];
  const auto action = [&](Action::Op op, const char* usage, const char* first, const char* second, long long lo) {
    expect_arguments(r.id, words, 2, usage);
    r.command = Command::kAction;
    r.action.op = op;
    r.action.a = int_argument(r.id, words[2], first, lo, 1'000'000);
    r.action.b = int_argument(r.id, words[3], second, lo, 1'000'000);
  };
  if (name == "hello" || name == "ping" || name == "status" || name == "capture" || name == "vent" ||
      name == "truth") {
    expect_arguments(r.id, words, 0, "");
    r.command = name == "hello"     ? Command::kHello
                : name == "ping"    ? Command::kPing
                : name == "status"  ? Command::kStatus
                : name == "capture" ? Command::kCapture
                : name == "truth"   ? Command::kTruth
                                    : Command::kVent;
  } else if (name == "set_pressure") {
    expect_arguments(r.id, words, 1, "PA");
    const auto pa = read_double(words[2], false);
    if (!pa) malformed(r.id, "pressure " + quote(words[2]) + " is not a finite number of Pa");
    r.command = Command::kAction;
    r.action = Action::set_pressure(*pa);
  } else if (name == "jam") {
    action(Action::Op::kJam, "R C", "cell row", "cell col", -1'000'000);
  } else if (name == "unjam") {
    action(Action::Op::kUnjam, "R C", "cell row", "cell col", -1'000'000);
  } else if (name == "pin") {
    action(Action::Op::kPin, "A B", "node a", "node b", -1'000'000);
  } else if (name == "unpin") {
    action(Action::Op::kUnpin, "A B", "node a", "node b", -1'000'000);
  } else if (name == "fault") {
    if (words.size() < 3) malformed(r.id, "fault needs a kind: drop, stall MS, mute MS or refuse N");
    r.command = Command::kFault;
    if (words[2] == "drop") {
      if (words.size() != 3) malformed(r.id, "fault drop takes no value");
      r.fault.kind = Fault::Kind::kDrop;
    } else if (words[2] == "stall" || words[2] == "mute") {
      if (words.size() != 4) malformed(r.id, "fault " + std::string(words[2]) + " takes one value (MS)");
      r.fault.kind = words[2] == "stall" ? Fault::Kind::kStall : Fault::Kind::kMute;
      r.fault.ms = int_argument(r.id, words[3], "fault duration (ms)", 0, 600'000);
    } else if (words[2] == "refuse") {
      if (words.size() != 4) malformed(r.id, "fault refuse takes one value (N, the action to refuse)");
      r.fault.kind = Fault::Kind::kRefuse;
      r.fault.actions = int_argument(r.id, words[3], "fault refuse action count", 1, 1'000'000);
    } else {
      malformed(r.id, "unknown fault " + quote(words[2]) + ": expected drop, stall MS, mute MS or refuse N");
    }
  } else {
    throw ProtocolError(ErrorCode::kUnknownCommand, r.id,
                        "unknown command " + quote(name) +
                            ": expected hello, ping, status, capture, vent, set_pressure, jam, unjam, pin, unpin, "
                            "fault or truth");
  }
  return r;
}

std::string format_ok(std::uint64_t id, std::string_view payload) {
  std::string out = "ok " + std::to_string(id);
  if (!payload.empty()) {
    out += ' ';
    out += payload;
  }
  return out;
}

std::string format_err(std::uint64_t id, ErrorCode code, std::string_view message) {
  std::string out = "err " + std::to_string(id) + ' ' + error_code_name(code) + ' ';
  for (const char c : message) out += (c == '\n' || c == '\r') ? ' ' : c;
  return out;
}

Reply parse_reply(std::string_view line) {
  Reply reply;
  const std::size_t first = line.find(' ');
  const std::string_view status = line.substr(0, first);
  if (status != "ok" && status != "err")
    malformed(0, "reply " + quote(line) + " starts with neither ok nor err");
  reply.ok = status == "ok";
  if (first == std::string_view::npos) malformed(0, "reply " + quote(line) + " has no request id");
  std::string_view rest = line.substr(first + 1);
  const std::size_t second = rest.find(' ');
  const std::string_view id_text = rest.substr(0, second);
  // 0 answers a request whose id could not be read.
  if (id_text == "0") reply.id = 0;
  else if (const auto id = read_id(id_text)) reply.id = *id;
  else malformed(0, "reply request id " + quote(id_text) + " is not a whole number");
  rest = second == std::string_view::npos ? std::string_view() : rest.substr(second + 1);
  if (reply.ok) {
    reply.text = std::string(rest);
    return reply;
  }
  const std::size_t third = rest.find(' ');
  reply.code = std::string(rest.substr(0, third));
  if (reply.code.empty()) malformed(reply.id, "err reply without a CODE");
  reply.text = third == std::string_view::npos ? std::string() : std::string(rest.substr(third + 1));
  return reply;
}

std::string format_hello(const Hello& h) {
  std::ostringstream out;
  out << "protocol=" << h.protocol << " rows=" << h.rows << " cols=" << h.cols
      << " cell_mm=" << format_double(h.cell_mm) << " max_pressure_pa=" << format_double(h.max_pressure_pa)
      << " grid=" << grid_text(h.grid, ',');
  return out.str();
}

Hello parse_hello(std::string_view payload) {
  const auto words = split_words(payload);
  Hello h;
  h.protocol = key_int(words, "protocol", "hello", 1, 1'000'000);
  h.rows = key_int(words, "rows", "hello", 1, 100'000);
  h.cols = key_int(words, "cols", "hello", 1, 100'000);
  h.cell_mm = key_double(words, "cell_mm", "hello");
  h.max_pressure_pa = key_double(words, "max_pressure_pa", "hello");
  h.grid = read_grid(split_on(require_key(words, "grid", "hello"), ','), "hello");
  return h;
}

std::string format_status(const StatusPayload& s) {
  return "pressure_pa=" + format_double(s.pressure_pa) + " jammed=" + bits(s.cell_jammed) +
         " pinned=" + bits(s.node_pinned);
}

StatusPayload parse_status(std::string_view payload, int rows, int cols) {
  const auto words = split_words(payload);
  StatusPayload s;
  s.pressure_pa = key_double(words, "pressure_pa", "status");
  s.cell_jammed = read_bits(require_key(words, "jammed", "status"), static_cast<std::size_t>(rows) * cols, "jammed");
  s.node_pinned =
      read_bits(require_key(words, "pinned", "status"), static_cast<std::size_t>(rows + 1) * (cols + 1), "pinned");
  return s;
}

std::string format_capture(const Capture& c) {
  if (c.heights_mm.rows() != c.grid.ny || c.heights_mm.cols() != c.grid.nx)
    throw std::invalid_argument("format_capture: heights are not ny x nx");
  std::string out = "frame " + grid_text(c.grid, ' ') + ' ';
  out.reserve(out.size() + static_cast<std::size_t>(c.grid.nx) * c.grid.ny * 8);
  for (int iy = 0; iy < c.grid.ny; ++iy)
    for (int ix = 0; ix < c.grid.nx; ++ix) {
      if (iy || ix) out += ',';
      out += format_double(c.heights_mm(iy, ix));
    }
  return out;
}

Capture parse_capture(std::string_view payload) {
  const auto words = split_words(payload);
  if (words.empty() || words[0] != "frame") malformed(0, "capture: payload does not start with \"frame\"");
  if (words.size() != 8) malformed(0, "capture: expected frame NX NY X0 Y0 DX DY VALUES");
  Capture c;
  c.grid = read_grid({words.begin() + 1, words.begin() + 7}, "capture");
  c.heights_mm.resize(c.grid.ny, c.grid.nx);
  std::string_view values = words[7];
  long i = 0;
  const long n = static_cast<long>(c.grid.nx) * c.grid.ny;
  while (true) {
    const std::size_t end = values.find(',');
    const std::string_view field = values.substr(0, end);
    if (i >= n) malformed(0, "capture: more than " + std::to_string(n) + " samples");
    const auto v = read_double(field, true);
    if (!v)
      malformed(0, "capture: sample " + std::to_string(i) + " (row " + std::to_string(i / c.grid.nx) + ", column " +
                       std::to_string(i % c.grid.nx) + ") " + quote(field) + " is not a number or nan");
    c.heights_mm(i / c.grid.nx, i % c.grid.nx) = *v;
    ++i;
    if (end == std::string_view::npos) break;
    values.remove_prefix(end + 1);
  }
  if (i != n) malformed(0, "capture: " + std::to_string(i) + " samples, expected " + std::to_string(n));
  return c;
}

}  // namespace hj::device::protocol
