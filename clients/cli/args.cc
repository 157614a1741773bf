#include "args.h"

#include <cmath>
#include <stdexcept>

namespace hj::cli {

double parse_number(const std::string& flag, const std::string& text) {
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value))
    throw std::invalid_argument(flag + " needs a finite number, got \"" + text + "\"");
  return value;
}

int parse_int(const std::string& flag, const std::string& text, int lo, int hi) {
  size_t used = 0;
  long v = 0;
  try {
    v = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || v < lo || v > hi)
    throw std::invalid_argument(flag + " needs a whole number from " + std::to_string(lo) + " to " +
                                std::to_string(hi) + ", got \"" + text + "\"");
  return static_cast<int>(v);
}

}  // namespace hj::cli
