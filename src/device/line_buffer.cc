#include "device/line_buffer.h"

namespace hj::device {

void LineBuffer::feed(std::string_view bytes, const std::function<void(std::string_view)>& on_line,
                      const std::function<void()>& on_overflow) {
  while (!bytes.empty()) {
    const std::size_t end = bytes.find('\n');
    const std::string_view chunk = bytes.substr(0, end);
    if (!skipping_) {
      partial_.append(chunk);
      // Over the limit (a "\r" before the newline is not counted).
      const std::size_t length = (end != std::string_view::npos && !partial_.empty() && partial_.back() == '\r')
                                     ? partial_.size() - 1
                                     : partial_.size();
      if (length > max_line_bytes_ + (end == std::string_view::npos ? 1 : 0)) {
        partial_.clear();
        skipping_ = true;
        on_overflow();
      }
    }
    if (end == std::string_view::npos) return;
    if (!skipping_) {
      std::string_view line(partial_);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      on_line(line);
    }
    partial_.clear();
    skipping_ = false;
    bytes.remove_prefix(end + 1);
  }
}

void LineBuffer::clear() {
  partial_.clear();
  skipping_ = false;
}

}  // namespace hj::device
