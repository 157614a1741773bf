// Device link round trips over loopback against the in-process emulator
// (3 x 4 array, p = 4, 77 x 58 capture grid): a ping (the protocol and the
// link alone), a capture (rasterise + about 80 kB of text each way + parse),
// and an action followed by a capture (a settle included).
// Run: ./build/hj_bench --benchmark_filter=Device
#include <benchmark/benchmark.h>

#include "../device_test_support.h"
#include "device/asio_device_link.h"

namespace {

using namespace std::chrono_literals;
using hj::Action;

struct LinkedDevice {
  LinkedDevice() : link(hj::device::parse_endpoint(device.endpoint())) {
    link.start();
    if (!hj::testing_support::eventually([&] { return link.connected(); }))
      throw std::runtime_error("device bench: the link did not come up");
  }
  hj::testing_support::EmulatedDevice device;
  hj::device::AsioDeviceLink link;
};

void BM_DevicePing(benchmark::State& state) {
  LinkedDevice d;
  for (auto _ : state) d.link.ping(5s);
}

void BM_DeviceCapture(benchmark::State& state) {
  LinkedDevice d;
  d.link.execute(Action::set_pressure(1000.0), 30s);
  for (auto _ : state) benchmark::DoNotOptimize(d.link.capture(30s));
}

// Alternates between two nearby pressures so every action really settles.
void BM_DeviceActionThenCapture(benchmark::State& state) {
  LinkedDevice d;
  d.link.execute(Action::set_pressure(1000.0), 30s);
  bool high = false;
  for (auto _ : state) {
    high = !high;
    d.link.execute(Action::set_pressure(high ? 1100.0 : 1000.0), 30s);
    benchmark::DoNotOptimize(d.link.capture(30s));
  }
}

BENCHMARK(BM_DevicePing)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DeviceCapture)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DeviceActionThenCapture)->Unit(benchmark::kMillisecond);

}  // namespace
