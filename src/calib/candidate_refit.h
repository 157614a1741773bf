// Refitting the candidates of one round of diagnose's selection
// (selection.h): the most promising first, each from the current optimum
// (or the scan's start), cross-validated and judged, then searched over its
// parameters' ranges where the local refit leaves the data unexplained.
#pragma once

#include <vector>

#include "calib/selection.h"

namespace hj {

// Refits the candidates the screening let through, the most promising
// first, so that one that cannot come near the best refitted one need not
// be refitted (refit_cutoff, refit_cutoff_explained); then searches the
// unexplained ones for a better basin where that may pay (selection.h,
// worth_a_basin_search; max_basin_searches). fits.front() is the best
// significant refit; a candidate the model cannot replay is said so in
// out.skipped.
void refit_candidates(Selection& s, std::vector<CandidateFit>& to_refit, std::vector<CandidateFit>& fits);

// After the current model was refitted to a better optimum (like with
// like), a candidate fitted from the old one may end above it, though a
// model that extends the current one can always match it: its fit stopped
// in the old optimum's basin. It is refitted from the new optimum with its
// effect where its fit left it; true (c's fit, held-out RMSE and note
// replaced) if that fits better. Its delta BIC and significance are the
// caller's to redo.
bool refit_from_rebased_current(Selection& s, CandidateFit& c);

}  // namespace hj
