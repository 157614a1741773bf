#include "calib/gain_by_capture.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "calib/least_squares.h"

namespace hj {

CaptureGain largest_capture_gain(const Dataset& dataset, const Eigen::VectorXd& before, const Eigen::VectorXd& after) {
  const std::vector<long> rows = capture_rows(dataset);
  if (before.size() != rows.back() || after.size() != rows.back())
    throw std::invalid_argument("largest_capture_gain: residuals of " + std::to_string(before.size()) + " and " +
                                std::to_string(after.size()) + " rows for a dataset of " +
                                std::to_string(rows.back()) + " measured samples");
  CaptureGain out;
  double best_fall = 0.0;
  int row = 0;
  for (int s = 0; s < static_cast<int>(dataset.sessions.size()); ++s)
    for (int k = 0; k < static_cast<int>(dataset.sessions[s].captures.size()); ++k, ++row) {
      const long begin = rows[row], count = rows[row + 1] - rows[row];
      if (count == 0) continue;
      const double b = before.segment(begin, count).squaredNorm(), a = after.segment(begin, count).squaredNorm();
      if (b - a > best_fall) {
        best_fall = b - a;
        out.session = s;
        out.capture = k;
        out.before_rmse_mm = std::sqrt(b / count);
        out.after_rmse_mm = std::sqrt(a / count);
      }
    }
  const double total_fall = before.squaredNorm() - after.squaredNorm();
  out.share = total_fall > 0.0 ? best_fall / total_fall : std::numeric_limits<double>::quiet_NaN();
  return out;
}

std::string capture_name(const Dataset& dataset, int session, int capture) {
  const MeasuredSession& s = dataset.sessions.at(session);
  const MeasuredCapture& c = s.captures.at(capture);
  char pressure[40];
  std::snprintf(pressure, sizeof pressure, " (%.3f kPa)", c.pressure_pa / 1000.0);
  return s.session.name + " " + c.frame + pressure;
}

}  // namespace hj
