// The greedy forward selection diagnose() runs (diagnosis.cc), shared by
// its steps: the candidates' refits (candidate_refit.cc) and the rounds.
// Internal to diagnose.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "calib/diagnosis.h"

namespace hj {

// The greedy forward selection diagnose() runs: the effects chosen so far
// and the fit of the model they make, against which candidates are judged.
struct Selection {
  const Dataset& dataset;
  const DiagnoseOptions& options;
  const DiagnoseProgress& progress;
  Diagnosis& out;
  std::vector<std::string> chosen;
  LeastSquaresResult current;
  double current_heldout = 0.0;
  // A significant candidate refitted in this round already explains the
  // data (goodness of fit): the others need no search over their ranges.
  bool round_explained = false;
  // The least misfit above the noise floor (RMSE^2 - floor^2, mm^2) that a
  // significant candidate refitted in this round leaves.
  double round_best_excess_mm2 = std::numeric_limits<double>::infinity();
  // Each candidate's optimum from the last round where it was significant
  // and not chosen: a start for its search in a later round.
  std::map<std::string, ModelParams> earlier_optima = {};
};

// Significance. BIC's penalty is ln n per parameter (about 12 for the
// 1.7e5 samples of a six-session dataset); delta BIC below -10 is "very
// strong" evidence on the Kass-Raftery scale. With that many samples BIC
// alone would still accept an effect that only soaks up a systematic
// misfit of a few hundredths of a mm, so the effect must also lower the
// error on sessions it was not fitted to by a real margin: 1 % of the RMSE
// is about six standard errors of an RMSE estimated from 1.7e5 samples
// (relative s.e. 1 / sqrt(2 n)), and far less than any effect worth
// modelling changes.
// It must also remove a material share of what the current model leaves
// above the noise floor (DiagnoseOptions::min_excess_share).
struct SignificanceTests {
  bool heldout = false;   // the held-out RMSE falls by min_heldout_gain
  bool bic = false;       // delta BIC below max_delta_bic
  bool fit = false;       // the in-sample RMSE falls by min_fit_gain, or delta BIC below strong_delta_bic
  bool material = false;  // min_excess_share of the misfit above the floor removed
  bool all() const { return heldout && bic && fit && material; }
  // All but the held-out test pass / all but materiality pass.
  bool only_heldout_fails() const { return !heldout && bic && fit && material; }
  bool only_material_fails() const { return heldout && bic && fit && !material; }
};
SignificanceTests significance_tests(const CandidateFit& c, const Selection& s);
bool is_significant(const CandidateFit& c, const Selection& s);

// The order of a round's candidates, best first: the significant ones by
// delta BIC, then the rest by held-out RMSE. Every significant candidate has
// passed the held-out test; between them the held-out figures are too coarse
// to rank (a few folds, each one step or the full optimum where the step was
// dropped, so one candidate's figure can be in-sample and another's truly
// held out: an off-form soft cell's cell_defect held out at 1.59 mm against
// cell_stiffness's 1.45, in-sample 1.35 against 1.45).
bool ranks_before(const CandidateFit& a, const CandidateFit& b);

// Refits c's fold that holds out session k for real (fold_refit.h) and sets
// its held-out figures from it (fold_step[k] = -1); says so in notes.
void refit_fold_of(Selection& s, const std::vector<FitParameter>& parameters, int k, CandidateFit& c);

// The share of the current model's misfit above the noise floor (RMSE^2 -
// floor^2) that c's fit removes; 1 where the current model is at or below
// the floor (then there is no misfit to share out).
double excess_share_removed(const CandidateFit& c, const Selection& s);

// A fit's misfit above the noise floor: RMSE^2 - floor^2 (mm^2), at least 0.
double excess_mm2(const LeastSquaresResult& fit, const Selection& s);

// Whether c's local refit is worth a search for a better basin (a range
// search, an optimum probe): it leaves the data unexplained, no significant
// candidate of the round explains them, and none leaves a misfit above the
// floor search_excess_ratio times smaller than c's (DiagnoseOptions).
// strict (a refit from the candidate's earlier optimum, one refit): its
// residuals failing the chi-square test suffices, whatever the floor's
// tolerance says (a pressure offset absorbed into the mass left 1.087 mm
// against a 1.041 floor, within the tolerance).
bool worth_a_basin_search(const Selection& s, const CandidateFit& c, bool strict = false);

}  // namespace hj
