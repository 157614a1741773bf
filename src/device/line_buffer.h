// Splits a byte stream into protocol lines (src/device/PROTOCOL.md): "\n"
// ends a line, a "\r" before it is dropped, and a line longer than the limit
// is reported once and skipped up to its newline instead of growing without
// bound. Used by both ends of the link.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace hj::device {

class LineBuffer {
 public:
  explicit LineBuffer(std::size_t max_line_bytes) : max_line_bytes_(max_line_bytes) {}

  // Feeds received bytes; calls on_line for each complete line (without its
  // line end) and on_overflow once for each line that exceeded the limit.
  void feed(std::string_view bytes, const std::function<void(std::string_view line)>& on_line,
            const std::function<void()>& on_overflow);
  // Forgets a partial line (after a reconnect).
  void clear();

 private:
  std::size_t max_line_bytes_;
  std::string partial_;
  bool skipping_ = false;  // inside an over-long line, until its newline
};

}  // namespace hj::device
