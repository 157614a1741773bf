// A diagnosis's candidate before its refit: where the refit starts, and the
// screening's verdict on whether it is worth refitting at all (screening.h
// predicts the figures; this judges them as diagnose() would judge a
// refit, and replays the held-out sessions where the prediction cannot be
// trusted).
#pragma once

#include <string>
#include <vector>

#include "calib/diagnosis.h"

namespace hj {

// Where the candidate's refit starts: the scan's best point if it moved,
// the current optimum with the effect at its registry defaults, then at its
// lower and upper bounds (area_pressure's default does not replay).
std::vector<ModelParams> candidate_starts(const CandidateFit& c, const ModelParams& current,
                                          const std::vector<FitParameter>& parameters);

// True (and the predicted figures in c, marked screened_out) if the
// screening predicts that c cannot pass the acceptance, so that it is not
// refitted; false where the refit must decide.
bool screen_out(const Dataset& dataset, const LeastSquaresResult& current, double current_heldout,
                const std::vector<FitParameter>& parameters, const DiagnoseOptions& options, CandidateFit& c);

}  // namespace hj
