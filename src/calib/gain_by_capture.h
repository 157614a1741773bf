// Where an effect's gain comes from, capture by capture. A gain that rests
// on one capture may be the model's sensitivity there, not the effect: on
// synthetic jam_contraction + pressure_offset, pressure_offset's refit,
// gain 1.0005 and offset 0 Pa, lowered the RMSE from 1.100 to 1.086 mm,
// all of it in one capture at 0.241 kPa, 2 Pa below the fitted model's
// levelling pressure, where the sagging net's shape turns on a fraction of
// a pascal (RMSE 1.300 -> 1.061 mm there, no other capture moved by 0.005).
#pragma once

#include <Eigen/Core>
#include <string>

#include "calib/dataset.h"

namespace hj {

struct CaptureGain {
  int session = -1, capture = -1;  // the capture whose sum of squares fell most; -1 if none fell
  double before_rmse_mm = 0.0, after_rmse_mm = 0.0;
  // Its fall over the whole dataset's fall (can exceed 1 where other
  // captures rose); NaN if the whole did not fall.
  double share = 0.0;
};

// before, after: residuals laid out as dataset_residuals() lays them out
// (capture_rows()). @throws std::invalid_argument if either does not.
CaptureGain largest_capture_gain(const Dataset& dataset, const Eigen::VectorXd& before, const Eigen::VectorXd& after);

// "unjammed-sweep frames/001.csv (0.241 kPa)".
std::string capture_name(const Dataset& dataset, int session, int capture);

}  // namespace hj
