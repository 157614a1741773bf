// Screening a closed loop's corrected plan before the device runs it. The
// planner can answer a small change of its targets with a very different
// plan (a 6 x 8 ridge: a corrected plan that ended in the jammed sag, 52 mm
// from the goal after a 4 mm first run), so a corrected plan runs only if
// what the device is expected to make of it is not clearly worse than the
// best run so far; otherwise the correction is halved and replanned.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/action.h"

namespace hj {

struct CorrectionScreenOptions {
  // A plan passes when its expected MAE is at most this times the best
  // measured MAE so far (the expectation carries the last capture's noise).
  double tolerance = 1.25;
  int max_halvings = 3;  // past them the loop ends at its best

  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// What the device is expected to make of a plan: its predicted surface
// moved by the misfit the device showed on the last run, predicted_next +
// (last_measured - last_predicted), at the mesh points (NaN where the last
// capture saw nothing).
// @throws std::invalid_argument when the shapes differ.
Eigen::MatrixXd expected_outcome(const Eigen::MatrixXd& predicted_next_mm, const Eigen::MatrixXd& last_measured_mm,
                                 const Eigen::MatrixXd& last_predicted_mm);

// The targets with the correction since `previous` halved: the midpoint.
// @throws std::invalid_argument when the shapes differ.
Eigen::MatrixXd halved_correction(const Eigen::MatrixXd& previous_mm, const Eigen::MatrixXd& corrected_mm);

// After a device refused step `refused` of `steps`: if that step raised the
// pressure, the pressure the device stood at before it, which later plans
// should not pass (the refusal says the device cannot settle above it);
// infinity if the step raised no pressure, or if the pressure before it is
// below floor_pa (near levelling a plan must still carry the net past its sag).
double pressure_limit_after_refusal(const std::vector<Action>& steps, size_t refused, double floor_pa);

// True if a plan expected at expected_mae may run after a best of best_mae.
// @throws std::invalid_argument on a negative or non-finite best, or bad options.
bool passes_screen(double expected_mae, double best_mae, const CorrectionScreenOptions& options = {});

}  // namespace hj
