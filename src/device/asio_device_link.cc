#include "device/asio_device_link.h"

#include "device/asio_device_link_impl.h"

namespace hj::device {

AsioDeviceLink::AsioDeviceLink(Endpoint endpoint, LinkOptions options) {
  options.validate();
  impl_ = std::make_unique<Impl>(std::move(endpoint), options);
}

AsioDeviceLink::~AsioDeviceLink() { stop(); }

void AsioDeviceLink::start() {
  if (impl_->thread.joinable()) return;
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = false;
  }
  impl_->io.restart();
  impl_->work.emplace(impl_->io.get_executor());
  asio::post(impl_->io, [this] { impl_->connect(); });
  impl_->thread = std::thread([this] { impl_->io.run(); });
  impl_->notify_io.restart();
  impl_->notify_work.emplace(impl_->notify_io.get_executor());
  impl_->notify_thread = std::thread([this] { impl_->notify_io.run(); });
}

void AsioDeviceLink::stop() {
  if (!impl_->thread.joinable()) return;
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
  }
  asio::post(impl_->io, [this] {
    Impl& d = *impl_;
    {
      std::lock_guard lock(d.mutex);
      ++d.generation;
      d.up = false;
      d.status.connected = false;
    }
    d.close();
    d.reconnect_timer.cancel();
    d.fail_pending("the link was stopped");
    d.io.stop();
  });
  impl_->thread.join();
  impl_->work.reset();
  // Callbacks already queued still run, before stop() returns.
  impl_->notify_work.reset();
  impl_->notify_thread.join();
}

bool AsioDeviceLink::connected() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->up;
}

void AsioDeviceLink::execute(const Action& action, std::chrono::milliseconds timeout) {
  protocol::Request r;
  r.command = protocol::Command::kAction;
  r.action = action;
  std::string command = protocol::format_request(r);
  command = command.substr(command.find(' ') + 1);  // without the placeholder id
  std::uint64_t vents_before = 0;
  {
    std::lock_guard lock(impl_->mutex);
    vents_before = impl_->vents_mirrored;
  }
  impl_->request(command, timeout, /*actuates=*/true);
  // Acknowledged: mirror it, unless a vent has been mirrored since.
  std::lock_guard lock(impl_->mutex);
  if (impl_->vents_mirrored == vents_before) mirror_action(impl_->status, action);
}

Capture AsioDeviceLink::capture(std::chrono::milliseconds timeout) {
  const protocol::Reply reply = impl_->request("capture", timeout);
  Capture c;
  try {
    c = protocol::parse_capture(reply.text);
  } catch (const protocol::ProtocolError& e) {
    throw DeviceError(Kind::kRefused, std::string("device sent a bad capture: ") + e.what());
  }
  std::lock_guard lock(impl_->mutex);
  impl_->status.last_capture = c;
  return c;
}

void AsioDeviceLink::vent(std::chrono::milliseconds timeout) {
  impl_->request("vent", timeout);
  std::lock_guard lock(impl_->mutex);
  ++impl_->vents_mirrored;
  mirror_vent(impl_->status);
}

void AsioDeviceLink::halt_and_vent(std::chrono::milliseconds timeout) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->halted = true;
  }
  vent(timeout);
}

void AsioDeviceLink::release_halt() {
  std::lock_guard lock(impl_->mutex);
  impl_->halted = false;
}

DeviceStatus AsioDeviceLink::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status;
}

void AsioDeviceLink::on_connection_change(std::function<void(bool)> callback) {
  std::lock_guard lock(impl_->mutex);
  impl_->callback = std::move(callback);
}

DeviceStatus AsioDeviceLink::query_status(std::chrono::milliseconds timeout) {
  const protocol::Reply reply = impl_->request("status", timeout);
  std::lock_guard lock(impl_->mutex);
  DeviceStatus& s = impl_->status;
  try {
    const protocol::StatusPayload p = protocol::parse_status(reply.text, s.rows, s.cols);
    s.pressure_pa = p.pressure_pa;
    s.cell_jammed = p.cell_jammed;
    s.node_pinned = p.node_pinned;
  } catch (const protocol::ProtocolError& e) {
    throw DeviceError(Kind::kRefused, std::string("device sent a bad status: ") + e.what());
  }
  return s;
}

void AsioDeviceLink::ping(std::chrono::milliseconds timeout) { impl_->request("ping", timeout); }

std::string AsioDeviceLink::send_raw(const std::string& command, std::chrono::milliseconds timeout) {
  return impl_->request(command, timeout).text;
}

}  // namespace hj::device
