// A one-line progress bar on stderr, redrawn in place on a terminal and
// printed as plain lines (at most every 10 %) when stderr is a file or pipe.
#pragma once

#include <string>

namespace hj::cli {

class ProgressLine {
 public:
  explicit ProgressLine(std::string task);
  void update(int done, int total, const std::string& detail);
  void finish();

 private:
  std::string task_;
  bool tty_;
  int last_decile_ = -1;
};

}  // namespace hj::cli
