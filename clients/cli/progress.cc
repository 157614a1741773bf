#include "progress.h"

#include <unistd.h>

#include <cstdio>

namespace hj::cli {

ProgressLine::ProgressLine(std::string task) : task_(std::move(task)), tty_(isatty(fileno(stderr)) != 0) {}

void ProgressLine::update(int done, int total, const std::string& detail) {
  const int percent = total > 0 ? 100 * done / total : 100;
  if (tty_) {
    constexpr int kWidth = 24;
    const int filled = kWidth * percent / 100;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% %d/%d %-40.40s", task_.c_str(), filled, "########################",
                 kWidth - filled, "", percent, done, total, detail.c_str());
  } else if (percent / 10 != last_decile_) {
    last_decile_ = percent / 10;
    std::fprintf(stderr, "%s: %d/%d (%d%%) %s\n", task_.c_str(), done, total, percent, detail.c_str());
  }
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (tty_) std::fprintf(stderr, "\n");
}

}  // namespace hj::cli
