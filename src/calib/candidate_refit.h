// Refitting the candidates of one round of diagnose's selection
// (selection.h): the most promising first, each from the current optimum
// (or the scan's start), searched over its parameter's range where the
// local refit leaves the data unexplained, then cross-validated and judged.
#pragma once

#include <vector>

#include "calib/selection.h"

namespace hj {

// Refits the candidates the screening let through, the most promising
// first, so that one that cannot come near the best refitted one need not
// be refitted (refit_cutoff, refit_cutoff_explained). fits.front() is the
// best significant refit; a candidate the model cannot replay is said so in
// out.skipped.
void refit_candidates(Selection& s, std::vector<CandidateFit>& to_refit, std::vector<CandidateFit>& fits);

}  // namespace hj
