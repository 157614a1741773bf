// The device line protocol (src/device/PROTOCOL.md): exact formats, round
// trips, and malformed input that must come back as a ProtocolError naming
// what is wrong, never a crash or a silently wrong value.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "device/line_buffer.h"
#include "device/link_options.h"
#include "device/protocol.h"
#include "expect_error.h"

namespace hj::device {
namespace {

using protocol::Command;
using protocol::ErrorCode;
using protocol::ProtocolError;
using protocol::Request;
using testing_support::expect_error;

Request action_request(std::uint64_t id, const Action& a) {
  Request r;
  r.id = id;
  r.command = Command::kAction;
  r.action = a;
  return r;
}

TEST(DeviceProtocol, RequestsHaveTheDocumentedText) {
  EXPECT_EQ(protocol::format_request(action_request(7, Action::jam(0, 3))), "7 jam 0 3");
  EXPECT_EQ(protocol::format_request(action_request(8, Action::unpin(1, 2))), "8 unpin 1 2");
  EXPECT_EQ(protocol::format_request(action_request(9, Action::set_pressure(301.0))), "9 set_pressure 301");
  Request vent;
  vent.id = 10;
  vent.command = Command::kVent;
  EXPECT_EQ(protocol::format_request(vent), "10 vent");
  Request stall;
  stall.id = 11;
  stall.command = Command::kFault;
  stall.fault = {protocol::Fault::Kind::kStall, 250};
  EXPECT_EQ(protocol::format_request(stall), "11 fault stall 250");
}

TEST(DeviceProtocol, EveryRequestRoundTripsExactly) {
  std::vector<Request> requests;
  for (const Action& a : {Action::set_pressure(301.123456789012345), Action::set_pressure(0.0), Action::jam(2, 3),
                          Action::unjam(0, 0), Action::pin(1, 2), Action::unpin(2, 1)})
    requests.push_back(action_request(42, a));
  for (const Command c : {Command::kHello, Command::kPing, Command::kStatus, Command::kCapture, Command::kVent}) {
    Request r;
    r.id = 18446744073709551615ull;  // the largest id
    r.command = c;
    requests.push_back(r);
  }
  for (const auto kind : {protocol::Fault::Kind::kDrop, protocol::Fault::Kind::kStall, protocol::Fault::Kind::kMute,
                          protocol::Fault::Kind::kRefuse}) {
    Request r;
    r.id = 3;
    r.command = Command::kFault;
    const bool timed = kind == protocol::Fault::Kind::kStall || kind == protocol::Fault::Kind::kMute;
    r.fault = {kind, timed ? 1500 : 0, kind == protocol::Fault::Kind::kRefuse ? 4 : 0};
    requests.push_back(r);
  }
  for (const Request& r : requests) {
    const std::string line = protocol::format_request(r);
    SCOPED_TRACE(line);
    const Request back = protocol::parse_request(line);
    EXPECT_EQ(back.id, r.id);
    EXPECT_EQ(back.command, r.command);
    if (r.command == Command::kAction) {
      EXPECT_EQ(back.action.op, r.action.op);
      EXPECT_EQ(back.action.pressure_pa, r.action.pressure_pa);  // bit for bit
      EXPECT_EQ(back.action.a, r.action.a);
      EXPECT_EQ(back.action.b, r.action.b);
    }
    if (r.command == Command::kFault) {
      EXPECT_EQ(back.fault.kind, r.fault.kind);
      EXPECT_EQ(back.fault.ms, r.fault.ms);
      EXPECT_EQ(back.fault.actions, r.fault.actions);
    }
  }
}

TEST(DeviceProtocol, ExtraSpacesTabsAndCarriageReturnsAreTolerated) {
  const Request r = protocol::parse_request("  5\tjam   1 2 ");
  EXPECT_EQ(r.id, 5u);
  EXPECT_EQ(r.action.op, Action::Op::kJam);
  EXPECT_EQ(r.action.a, 1);
  EXPECT_EQ(r.action.b, 2);
}

struct BadLine {
  std::string line;
  ErrorCode code;
  std::uint64_t id;  // the id the error is answered to
  std::vector<std::string> words;
};

TEST(DeviceProtocol, MalformedRequestsNameWhatIsWrong) {
  const std::vector<BadLine> cases = {
      {"ping", ErrorCode::kMalformed, 0, {"request id", "\"ping\""}},
      {"0 ping", ErrorCode::kMalformed, 0, {"request id", ">= 1"}},
      {"-3 ping", ErrorCode::kMalformed, 0, {"request id"}},
      {"18446744073709551616 ping", ErrorCode::kMalformed, 0, {"request id"}},
      {"7", ErrorCode::kMalformed, 7, {"missing command"}},
      {"7 frobnicate 1", ErrorCode::kUnknownCommand, 7, {"unknown command", "frobnicate"}},
      {"7 JAM 1 2", ErrorCode::kUnknownCommand, 7, {"JAM"}},
      {"7 jam 1", ErrorCode::kMalformed, 7, {"jam takes 2 arguments", "R C", "got 1"}},
      {"7 jam 1 2 3", ErrorCode::kMalformed, 7, {"got 3"}},
      {"7 jam x 1", ErrorCode::kMalformed, 7, {"cell row", "\"x\"", "whole number"}},
      {"7 pin 1 2.5", ErrorCode::kMalformed, 7, {"node b", "\"2.5\""}},
      {"7 unjam 1 99999999999", ErrorCode::kMalformed, 7, {"cell col", "outside"}},
      {"7 set_pressure", ErrorCode::kMalformed, 7, {"set_pressure takes 1 argument", "PA"}},
      {"7 set_pressure abc", ErrorCode::kMalformed, 7, {"pressure", "\"abc\"", "Pa"}},
      {"7 set_pressure nan", ErrorCode::kMalformed, 7, {"pressure", "finite"}},
      {"7 set_pressure inf", ErrorCode::kMalformed, 7, {"pressure", "finite"}},
      {"7 set_pressure 1e999", ErrorCode::kMalformed, 7, {"pressure"}},
      {"7 set_pressure 3O0", ErrorCode::kMalformed, 7, {"\"3O0\""}},
      {"7 ping now", ErrorCode::kMalformed, 7, {"ping takes 0 arguments", "got 1"}},
      {"7 fault", ErrorCode::kMalformed, 7, {"fault needs a kind"}},
      {"7 fault explode", ErrorCode::kMalformed, 7, {"unknown fault", "explode"}},
      {"7 fault stall", ErrorCode::kMalformed, 7, {"fault stall takes one value"}},
      {"7 fault stall -5", ErrorCode::kMalformed, 7, {"fault duration", "outside", "600000"}},
      {"7 fault drop now", ErrorCode::kMalformed, 7, {"fault drop takes no value"}},
      {"7 fault refuse", ErrorCode::kMalformed, 7, {"fault refuse takes one value"}},
      {"7 fault refuse 0", ErrorCode::kMalformed, 7, {"fault refuse action count", "outside"}},
      {"", ErrorCode::kMalformed, 0, {"empty line"}},
      {"7 " + std::string(2000, 'x'), ErrorCode::kTooLong, 0, {"2002 bytes", "1024"}},
      {"7 jam \x01\x02 1", ErrorCode::kMalformed, 7, {"\"??\""}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.line.substr(0, 60));
    try {
      protocol::parse_request(c.line);
      ADD_FAILURE() << "parsed";
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.code(), c.code) << e.what();
      EXPECT_EQ(e.id(), c.id);
      for (const auto& w : c.words)
        EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << w << " not in: " << e.what();
    }
  }
}

TEST(DeviceProtocol, RepliesRoundTrip) {
  EXPECT_EQ(protocol::format_ok(7), "ok 7");
  EXPECT_EQ(protocol::format_ok(7, "pong"), "ok 7 pong");
  EXPECT_EQ(protocol::format_err(7, ErrorCode::kUnsafe, "too\nhigh"), "err 7 unsafe too high");

  auto r = protocol::parse_reply("ok 7 a b  c");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.id, 7u);
  EXPECT_EQ(r.text, "a b  c");
  r = protocol::parse_reply("ok 8");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.text, "");
  r = protocol::parse_reply("err 0 too_long line exceeds 1024 bytes");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.id, 0u);
  EXPECT_EQ(r.code, "too_long");
  EXPECT_EQ(r.text, "line exceeds 1024 bytes");

  for (const std::string bad : {"", "ok", "yes 7", "ok x", "err 7", "ok -1", "OK 7"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(protocol::parse_reply(bad), ProtocolError);
  }
}

protocol::Hello sample_hello() {
  protocol::Hello h;
  h.rows = 3;
  h.cols = 4;
  h.cell_mm = 38.0;
  h.max_pressure_pa = 3450.0;
  h.grid = {77, 58, 0.0, -1.5, 2.0, 2.0};
  return h;
}

TEST(DeviceProtocol, HelloHasTheDocumentedTextAndRoundTrips) {
  const std::string text = protocol::format_hello(sample_hello());
  EXPECT_EQ(text, "protocol=1 rows=3 cols=4 cell_mm=38 max_pressure_pa=3450 grid=77,58,0,-1.5,2,2");
  const protocol::Hello back = protocol::parse_hello(text + " firmware=2.1");  // unknown keys skipped
  EXPECT_EQ(back.rows, 3);
  EXPECT_EQ(back.cols, 4);
  EXPECT_EQ(back.max_pressure_pa, 3450.0);
  EXPECT_EQ(back.grid.nx, 77);
  EXPECT_EQ(back.grid.y0_mm, -1.5);
  expect_error<ProtocolError>([] { protocol::parse_hello("protocol=1 rows=3 cols=4 cell_mm=38 grid=1,1,0,0,1,1"); },
                              {"hello", "max_pressure_pa"});
  expect_error<ProtocolError>(
      [] { protocol::parse_hello("protocol=1 rows=3 cols=4 cell_mm=38 max_pressure_pa=1 grid=1,1,0,0,0,1"); },
      {"hello", "grid dx", "positive"});
}

TEST(DeviceProtocol, StatusRoundTripsAndChecksLengths) {
  protocol::StatusPayload s;
  s.pressure_pa = 301.5;
  s.cell_jammed = {0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0};
  s.node_pinned.assign(20, 0);
  s.node_pinned[1 * 5 + 2] = 1;
  const std::string text = protocol::format_status(s);
  EXPECT_EQ(text, "pressure_pa=301.5 jammed=000100000000 pinned=00000001000000000000");
  const auto back = protocol::parse_status(text, 3, 4);
  EXPECT_EQ(back.pressure_pa, 301.5);
  EXPECT_EQ(back.cell_jammed, s.cell_jammed);
  EXPECT_EQ(back.node_pinned, s.node_pinned);
  expect_error<ProtocolError>([&] { protocol::parse_status(text, 3, 5); }, {"jammed", "12 flags", "expected 15"});
  expect_error<ProtocolError>([] { protocol::parse_status("pressure_pa=1 jammed=01 pinned=0002", 1, 1); },
                              {"jammed", "2 flags", "expected 1"});
  expect_error<ProtocolError>([] { protocol::parse_status("pressure_pa=1 jammed=0 pinned=0002", 1, 1); },
                              {"pinned", "flag 3", "not 0 or 1"});
}

TEST(DeviceProtocol, CapturesRoundTripBitForBitWithNaN) {
  Capture c;
  c.grid = {3, 2, 0.0, 0.0, 2.0, 2.0};
  c.heights_mm.resize(2, 3);
  c.heights_mm << -12.345678901234567, 0.1, std::numeric_limits<double>::quiet_NaN(), 1e-300, -0.0, 55.0;
  const std::string text = protocol::format_capture(c);
  EXPECT_EQ(text, "frame 3 2 0 0 2 2 -12.345678901234567,0.1,nan,1e-300,-0,55");
  const Capture back = protocol::parse_capture(text);
  EXPECT_EQ(back.grid.nx, 3);
  EXPECT_EQ(back.grid.ny, 2);
  for (int iy = 0; iy < 2; ++iy)
    for (int ix = 0; ix < 3; ++ix) {
      if (std::isnan(c.heights_mm(iy, ix))) EXPECT_TRUE(std::isnan(back.heights_mm(iy, ix)));
      else EXPECT_EQ(back.heights_mm(iy, ix), c.heights_mm(iy, ix));
    }
}

TEST(DeviceProtocol, BadCapturesNameTheSample) {
  expect_error<ProtocolError>([] { protocol::parse_capture("frame 2 2 0 0 1 1 1,2,3"); },
                              {"capture", "3 samples", "expected 4"});
  expect_error<ProtocolError>([] { protocol::parse_capture("frame 2 2 0 0 1 1 1,2,3,4,5"); },
                              {"more than 4 samples"});
  expect_error<ProtocolError>([] { protocol::parse_capture("frame 2 2 0 0 1 1 1,2,x,4"); },
                              {"sample 2", "row 1, column 0", "\"x\""});
  expect_error<ProtocolError>([] { protocol::parse_capture("frame 2 2 0 0 1 1 1,inf,3,4"); }, {"sample 1"});
  expect_error<ProtocolError>([] { protocol::parse_capture("frame 99999 99999 0 0 1 1 1"); }, {"exceeds"});
  expect_error<ProtocolError>([] { protocol::parse_capture("image 1 1 0 0 1 1 1"); }, {"frame"});
}

// Random bytes and every truncation and single-byte change of valid lines:
// each parser either succeeds or throws ProtocolError, nothing else.
TEST(DeviceProtocol, GarbageNeverCrashesAParser) {
  std::vector<std::string> inputs;
  const std::vector<std::string> valid = {
      "7 set_pressure 301.25", "8 jam 0 3", "9 fault stall 100", "ok 7 frame 2 1 0 0 2 2 1.5,nan",
      "err 9 unsafe unsafe pressure",
      "ok 1 protocol=1 rows=3 cols=4 cell_mm=38 max_pressure_pa=3450 grid=77,58,0,0,2,2",
      "ok 2 pressure_pa=0 jammed=000000000000 pinned=00000000000000000000"};
  std::mt19937 random(12345);
  for (const auto& v : valid) {
    for (std::size_t n = 0; n <= v.size(); ++n) inputs.push_back(v.substr(0, n));
    for (int k = 0; k < 200; ++k) {
      std::string m = v;
      m[random() % m.size()] = static_cast<char>(random() % 256);
      inputs.push_back(m);
    }
  }
  for (int k = 0; k < 500; ++k) {
    std::string junk(random() % 80, ' ');
    for (char& ch : junk) ch = static_cast<char>(random() % 256);
    inputs.push_back(junk);
  }
  int parsed = 0;
  for (const auto& in : inputs) {
    const auto attempt = [&](auto&& parse) {
      try {
        parse();
        ++parsed;
      } catch (const ProtocolError&) {
      }
    };
    attempt([&] { protocol::parse_request(in); });
    attempt([&] {
      const auto r = protocol::parse_reply(in);
      if (!r.ok) return;
      attempt([&] { protocol::parse_capture(r.text); });
      attempt([&] { protocol::parse_hello(r.text); });
      attempt([&] { protocol::parse_status(r.text, 3, 4); });
    });
  }
  EXPECT_GT(parsed, 0);  // the unmutated lines did parse
}

TEST(LineBuffer, SplitsChunksAnywhereAndDropsCarriageReturns) {
  LineBuffer buffer(16);
  std::vector<std::string> lines;
  int overflows = 0;
  const std::string stream = "1 ping\r\n2 jam 0 3\n\n3 vent\n4 par";
  for (const char ch : stream)
    buffer.feed(std::string_view(&ch, 1), [&](std::string_view l) { lines.emplace_back(l); }, [&] { ++overflows; });
  EXPECT_EQ(lines, (std::vector<std::string>{"1 ping", "2 jam 0 3", "", "3 vent"}));
  EXPECT_EQ(overflows, 0);
}

TEST(LineBuffer, AnOverlongLineIsReportedOnceAndSkipped) {
  LineBuffer buffer(8);
  std::vector<std::string> lines;
  int overflows = 0;
  const auto feed = [&](std::string_view s) {
    buffer.feed(s, [&](std::string_view l) { lines.emplace_back(l); }, [&] { ++overflows; });
  };
  feed("12345678\n");         // exactly the limit: fine
  feed("123456789");          // one over, no newline yet
  feed("0123456789012345");   // still the same line
  feed("789\n2 ping\n");
  EXPECT_EQ(overflows, 1);
  EXPECT_EQ(lines, (std::vector<std::string>{"12345678", "2 ping"}));
}

TEST(DeviceEndpoint, ParsesTcpAndSerialAndNamesWhatIsWrong) {
  Endpoint e = parse_endpoint("127.0.0.1:7700");
  EXPECT_EQ(e.kind, Endpoint::Kind::kTcp);
  EXPECT_EQ(e.host, "127.0.0.1");
  EXPECT_EQ(e.port, 7700);
  e = parse_endpoint("[::1]:80");
  EXPECT_EQ(e.host, "::1");
  EXPECT_EQ(e.to_string(), "[::1]:80");
  e = parse_endpoint("/dev/ttyUSB0");
  EXPECT_EQ(e.kind, Endpoint::Kind::kSerial);
  EXPECT_EQ(e.to_string(), "/dev/ttyUSB0");
  expect_error<std::invalid_argument>([] { parse_endpoint("localhost"); }, {"\"localhost\"", "no port"});
  expect_error<std::invalid_argument>([] { parse_endpoint("localhost:0"); }, {"port \"0\"", "1..65535"});
  expect_error<std::invalid_argument>([] { parse_endpoint("localhost:99999"); }, {"99999"});
  expect_error<std::invalid_argument>([] { parse_endpoint(":7700"); }, {"empty host"});
  expect_error<std::invalid_argument>([] { parse_endpoint("::1:7700"); }, {"brackets"});
}

TEST(DeviceLinkOptions, ValidationNamesTheField) {
  LinkOptions o;
  EXPECT_NO_THROW(o.validate());
  o.heartbeat_timeout = o.heartbeat_interval;
  expect_error<std::invalid_argument>([&] { o.validate(); }, {"heartbeat_timeout", "heartbeat_interval"});
  o = LinkOptions{};
  o.backoff_initial = std::chrono::milliseconds(0);
  expect_error<std::invalid_argument>([&] { o.validate(); }, {"backoff_initial", "ms"});
  o = LinkOptions{};
  o.backoff_factor = std::nan("");
  expect_error<std::invalid_argument>([&] { o.validate(); }, {"backoff_factor"});
}

}  // namespace
}  // namespace hj::device
