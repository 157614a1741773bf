// After the greedy selection: an effect chosen in an early round may be made
// redundant by one chosen later (a cell_defect chosen first while
// boundary_compliance was screened out, fitted back to 1.00 once
// boundary_compliance was in). Each chosen effect, the earliest first, is
// switched off at the final optimum and the dataset replayed there (one
// Jacobian, no refit); where that model's BIC is no higher, the effect does
// not pay for its parameters and is dropped from the verdict, with a note.
// Internal to diagnose.
#pragma once

#include "calib/selection.h"

namespace hj {

// Updates s.chosen, s.current and out.notes.
void drop_redundant_effects(Selection& s);

}  // namespace hj
