#include "sim/dead_end_watch.h"

#include "sim/mesh_folds.h"

namespace hj {

namespace {
constexpr std::size_t kMaxHistory = 400;
}  // namespace

bool DeadEndWatch::dead_end(const Eigen::Matrix3Xd& x, double residual_n) {
  const double sharpest = find_mesh_folds(*mesh_, x).sharpest_deg;
  if (sharpest > options_.refuse_fold_deg) {
    reason_ = "folded past the refusal angle";
    return true;
  }
  const bool stalled = options_.stall_steps > 0 && sharpest > options_.stall_fold_deg &&
                       (crawled(x, residual_n) || returned(x, residual_n));
  history_.push_back({x, residual_n, sharpest});
  if (history_.size() > kMaxHistory) history_.pop_front();
  if (!stalled) return false;
  reason_ = "stalled on a folded mesh";
  return true;
}

bool DeadEndWatch::returned(const Eigen::Matrix3Xd& x, double residual_n) const {
  const double near = options_.stall_move_fraction * mesh_->spacing();
  const int old_enough = static_cast<int>(history_.size()) - options_.stall_steps + 1;
  for (int i = 0; i < old_enough; ++i)
    if (still_near(history_[i], x, residual_n, near)) return true;
  return false;
}

bool DeadEndWatch::crawled(const Eigen::Matrix3Xd& x, double residual_n) const {
  const int first = static_cast<int>(history_.size()) - options_.stall_steps;
  if (first < 0) return false;
  for (int i = first; i < static_cast<int>(history_.size()); ++i)
    if (history_[i].sharpest_deg <= options_.stall_fold_deg) return false;
  return still_near(history_[first], x, residual_n, options_.crawl_move_fraction * mesh_->spacing());
}

bool DeadEndWatch::still_near(const Passed& passed, const Eigen::Matrix3Xd& x, double residual_n, double near) {
  return residual_n >= 0.5 * passed.residual_n && (x - passed.x).colwise().norm().maxCoeff() < near;
}

}  // namespace hj
