// Where a candidate's refit starts: the best of short joint fits over its
// new parameter's range and from the scan's start (multi_start.h).
#pragma once

#include <optional>

#include "calib/diagnosis.h"

namespace hj {

// Short joint fits from values spanning the new parameter's range and from
// the scan's start (multi_start.h); c.scanned_start becomes the best and
// c.starts_tried lists them. Does nothing for an effect multi_start skips
// or with options.multi_start.starts < 1, or when the fit's iteration cap
// is no longer than the short fits.
void start_from_best_of_range(const Dataset& dataset, const ModelParams& current, const DiagnoseOptions& options,
                              const DiagnoseProgress& progress, CandidateFit& c);

// After a local refit `local` of c: short joint fits from values spanning
// the new parameter's range, the other parameters at the local optimum
// (c.starts_tried lists them). Returns the best of them if its cost is
// already below the converged local fit's: the local fit then stopped in
// a worse basin than one the range holds. Nothing for an effect
// multi_start skips or with options.multi_start.starts < 1.
std::optional<ModelParams> better_start_than_local(const Dataset& dataset, const LeastSquaresResult& local,
                                                   const DiagnoseOptions& options, const DiagnoseProgress& progress,
                                                   CandidateFit& c);

}  // namespace hj
