#include "sim/dead_end_watch.h"

#include "sim/mesh_folds.h"

namespace hj {

bool DeadEndWatch::dead_end(const Eigen::Matrix3Xd& x, double residual_n) {
  const double sharpest = find_mesh_folds(*mesh_, x).sharpest_deg;
  if (sharpest > options_.refuse_fold_deg) {
    reason_ = "folded past the refusal angle";
    return true;
  }
  if (options_.stall_steps == 0 || sharpest <= options_.stall_fold_deg) {
    window_.clear();  // the count starts anew on the next folded step
    best_residual_ = 0.0;
    return false;
  }
  if (!stalled(x, residual_n)) return false;
  reason_ = "stalled on a folded mesh";
  return true;
}

bool DeadEndWatch::stalled(const Eigen::Matrix3Xd& x, double residual_n) {
  if (best_residual_ == 0.0 || residual_n < 0.5 * best_residual_) {
    best_residual_ = residual_n;
    steps_since_best_ = 0;
  } else {
    ++steps_since_best_;
  }
  window_.push_back(x);
  if (static_cast<int>(window_.size()) > options_.stall_steps + 1) window_.pop_front();
  if (static_cast<int>(window_.size()) <= options_.stall_steps || steps_since_best_ < options_.stall_steps)
    return false;
  const double net_move = (x - window_.front()).colwise().norm().maxCoeff();
  return net_move < options_.stall_move_fraction * mesh_->spacing();
}

}  // namespace hj
