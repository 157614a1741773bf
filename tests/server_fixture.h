// An in-process hapticjam server on a loopback port 0 for tests, with a
// channel to it, a fake device link, and goals to plan.
#pragma once

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "fake_device_link.h"
#include "hapticjam/v1/device_service.grpc.pb.h"
#include "hapticjam/v1/planning_service.grpc.pb.h"
#include "json_log.h"
#include "scratch_dir.h"
#include "server.h"

namespace hj::testing_support {

namespace v1 = ::hapticjam::v1;

// A smooth bump as a CSV height table (rows x cols values).
inline std::string bump_csv(int rows, int cols) {
  std::ostringstream s;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j)
      s << (j ? "," : "") << 100.0 * std::exp(-(std::pow(i - rows / 2.0, 2) + std::pow(j - cols / 3.0, 2)) / 30.0);
    s << "\n";
  }
  return s.str();
}

inline v1::ArraySpec array_spec(int rows, int cols, int segments = 4) {
  v1::ArraySpec a;
  a.set_rows(rows), a.set_cols(cols), a.set_segments(segments);
  return a;
}

inline v1::PreviewRequest preview_request(int rows, int cols, const std::string& csv = bump_csv(16, 20)) {
  v1::PreviewRequest r;
  *r.mutable_array() = array_spec(rows, cols);
  r.mutable_goal()->mutable_file()->set_content(csv);
  r.mutable_goal()->mutable_file()->set_file_name("bump.csv");
  return r;
}

inline v1::PlanRequest plan_request(int rows, int cols, const std::string& csv = bump_csv(16, 20)) {
  const v1::PreviewRequest p = preview_request(rows, cols, csv);
  v1::PlanRequest r;
  *r.mutable_array() = p.array();
  *r.mutable_goal() = p.goal();
  return r;
}

// A plan of device steps: "p 0.3" (kPa), "j r c", "u r c" (unjam), "n a b" (pin), "c" (capture).
inline v1::Plan device_plan(const std::vector<std::string>& steps) {
  v1::Plan plan;
  for (const auto& text : steps) {
    std::istringstream in(text);
    char op;
    double x = 0, y = 0;
    in >> op >> x >> y;
    v1::Step* s = plan.add_steps();
    if (op == 'p') s->mutable_set_pressure()->set_kpa(x);
    else if (op == 'j') s->mutable_jam()->set_row(int(x)), s->mutable_jam()->set_col(int(y));
    else if (op == 'u') s->mutable_unjam()->set_row(int(x)), s->mutable_unjam()->set_col(int(y));
    else if (op == 'n') s->mutable_pin()->set_a(int(x)), s->mutable_pin()->set_b(int(y));
    else if (op == 'c') s->mutable_capture();
  }
  return plan;
}

struct TestServer {
  explicit TestServer(server::ServerOptions options, bool with_device = true, int rows = 3, int cols = 4) {
    server::set_logging_enabled(false);
    if (options.listen.empty()) options.listen = "127.0.0.1:0";
    std::unique_ptr<device::DeviceLink> owned;
    if (with_device) {
      auto fake = std::make_unique<FakeDeviceLink>(rows, cols);
      link = fake.get();
      owned = std::move(fake);
    }
    server = std::make_unique<server::HapticServer>(options, std::move(owned));
    channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server->port()), grpc::InsecureChannelCredentials());
    planning = v1::PlanningService::NewStub(channel);
    device = v1::DeviceService::NewStub(channel);
  }

  FakeDeviceLink* link = nullptr;  // owned by the server
  std::unique_ptr<server::HapticServer> server;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::PlanningService::Stub> planning;
  std::unique_ptr<v1::DeviceService::Stub> device;
};

// A client context with a deadline (so no test can hang) and a token.
inline std::unique_ptr<grpc::ClientContext> call(const std::string& token = "", int seconds = 60) {
  auto c = std::make_unique<grpc::ClientContext>();
  c->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(seconds));
  if (!token.empty()) c->AddMetadata("authorization", "Bearer " + token);
  return c;
}

// Polls `done` every 5 ms for up to `seconds` (a bound against hanging, not
// a timing assertion); true once it holds.
template <typename F>
bool eventually(F done, double seconds = 20.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return done();
}

}  // namespace hj::testing_support
