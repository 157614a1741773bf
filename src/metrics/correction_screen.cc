#include "metrics/correction_screen.h"

#include <cmath>
#include <stdexcept>

#include "metrics/same_shape.h"

namespace hj {

Eigen::MatrixXd expected_outcome(const Eigen::MatrixXd& predicted_next_mm, const Eigen::MatrixXd& last_measured_mm,
                                 const Eigen::MatrixXd& last_predicted_mm) {
  check_same_shape(predicted_next_mm, last_measured_mm, "expected_outcome (prediction, last capture)");
  check_same_shape(last_measured_mm, last_predicted_mm, "expected_outcome (last capture, last prediction)");
  return predicted_next_mm + (last_measured_mm - last_predicted_mm);
}

Eigen::MatrixXd halved_correction(const Eigen::MatrixXd& previous_mm, const Eigen::MatrixXd& corrected_mm) {
  check_same_shape(previous_mm, corrected_mm, "halved_correction (previous, corrected targets)");
  return 0.5 * (previous_mm + corrected_mm);
}

void CorrectionScreenOptions::validate() const {
  if (!(tolerance >= 1.0) || !std::isfinite(tolerance))
    throw std::invalid_argument("CorrectionScreenOptions.tolerance must be a finite number >= 1");
  if (max_halvings < 0) throw std::invalid_argument("CorrectionScreenOptions.max_halvings must be >= 0");
}

bool passes_screen(double expected_mae, double best_mae, const CorrectionScreenOptions& options) {
  if (!(best_mae >= 0.0) || !std::isfinite(best_mae))
    throw std::invalid_argument("passes_screen: the best MAE must be a finite number of mm >= 0");
  options.validate();
  return expected_mae <= options.tolerance * best_mae;  // a NaN expectation never passes
}

double pressure_limit_after_refusal(const std::vector<Action>& steps, size_t refused, double floor_pa) {
  if (refused >= steps.size() || steps[refused].op != Action::Op::kSetPressure) return INFINITY;
  double before = 0.0;
  for (size_t k = 0; k < refused; ++k)
    if (steps[k].op == Action::Op::kSetPressure) before = steps[k].pressure_pa;
  return before > 0.0 && before >= floor_pa && before < steps[refused].pressure_pa ? before : INFINITY;
}

}  // namespace hj
