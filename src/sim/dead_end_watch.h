// Tells, step by step, whether a planner's flow has reached a dead end: a
// fold sharper than the refusal angle (the Eq. 3 normals there are nearly
// ill-defined), or a folded mesh on which the flow has stalled. There the
// follower pressure keeps working on the folded flaps, and the flow wanders
// in place without settling (a 9 x 12 plan's jammed sag at 250 Pa: 400 flow
// steps, each moving a point up to 1 mm, end within 1.5 mm of where step 40
// stood, the residual between 1e-3 and 3e-2 N), so the rest of its step
// budget buys nothing. A snap-through also passes folded states with a
// residual that does not fall, but it is going somewhere: a 5 x 7 jammed sag
// inverting into a dome at 350 Pa moves 20-30 mm every 20 steps. A flow may
// also cycle: a 9 x 12 plan's jammed sag at 250 Pa (Luxembourg) swings with
// a period of about 40 steps, folds coming and going around 120 degrees, and
// comes back within 0.4 mm of where it stood a period before. Both are a
// return: the flow stands, folded, near a state it passed at least
// stall_steps before, and its residual has not halved since. Before either
// returns it crawls: folded all the while, its points move at most 0.6-0.7
// of a mesh spacing in 20 steps (Luxembourg, the bunny) where the 5 x 7
// snap-through moves 2.1-3.4; that crawl, too, is a stall. (One folded crawl
// seen went on to settle, random goal 91 of docs/random-goals.md: refused.)
#pragma once

#include <Eigen/Core>
#include <deque>
#include <string>

#include "model/mesh.h"

namespace hj {

struct DeadEndWatchOptions {
  double refuse_fold_deg = 150.0;  // a fold past this ends the flow at once
  // Folded past stall_fold_deg, within stall_move_fraction of the mesh
  // spacing (every point) of a state it passed at least stall_steps accepted
  // steps before, folded or not, and with a residual above half of that
  // state's, the flow has stalled (stall_steps 0: never).
  double stall_fold_deg = 120.0;
  int stall_steps = 20;
  double stall_move_fraction = 0.25;
  // Folded past stall_fold_deg at every one of the last stall_steps accepted
  // steps, with every point within crawl_move_fraction of the spacing of
  // where it stood stall_steps before, and the residual above half of that
  // state's, the flow is crawling: stalled too.
  double crawl_move_fraction = 0.75;
};

class DeadEndWatch {
 public:
  DeadEndWatch(const Mesh& mesh, DeadEndWatchOptions options) : mesh_(&mesh), options_(options) {}

  // After each accepted flow step: true if the flow is a dead end.
  bool dead_end(const Eigen::Matrix3Xd& x, double residual_n);
  // Why the last dead_end() said true ("" before it did).
  const char* reason() const { return reason_; }

 private:
  // True if the flow is back near a state of history_ at least stall_steps old.
  bool returned(const Eigen::Matrix3Xd& x, double residual_n) const;
  // True if the flow has stayed folded and crawled for the last stall_steps.
  bool crawled(const Eigen::Matrix3Xd& x, double residual_n) const;

  const Mesh* mesh_;
  DeadEndWatchOptions options_;
  struct Passed {
    Eigen::Matrix3Xd x;
    double residual_n;
    double sharpest_deg;
  };
  // True if every point of x is within `near` of `passed` and the residual
  // has not halved since.
  static bool still_near(const Passed& passed, const Eigen::Matrix3Xd& x, double residual_n, double near);
  // Every accepted step's positions and residual, oldest first (at most
  // kMaxHistory: a planner's settle budget is smaller).
  std::deque<Passed> history_;
  const char* reason_ = "";
};

}  // namespace hj
