// Which effect is the model missing? Fit the baseline; refit with each
// candidate effect of the registry added; judge each by its cross-validated
// (leave-one-session-out) error and by BIC, so that an effect that only adds
// freedom is not chosen; then add effects greedily while one still helps.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "calib/cross_validation.h"
#include "calib/effect_scan.h"
#include "calib/fit_model.h"
#include "calib/goodness_of_fit.h"
#include "calib/multi_start.h"
#include "calib/residual_pattern.h"
#include "calib/screening.h"

namespace hj {

struct DiagnoseOptions {
  FitOptions fit;               // the baseline fit (levelling, Algorithm 1, joint)
  std::vector<std::string> candidates;  // empty: every non-baseline effect in the registry
  int max_effects = 3;          // greedy selection stops after this many
  // Significant = the held-out RMSE falls by at least this share of the
  // current model's AND delta BIC is below max_delta_bic AND the in-sample
  // RMSE falls by min_fit_gain (see diagnosis.cc).
  double min_heldout_gain = 0.01;
  double max_delta_bic = -10.0;
  // And the in-sample RMSE falls by at least this share too: a held-out
  // error that falls at an unchanged fit is the cross-validation folds'
  // doing, not the data's (on synthetic area_pressure data, jam_creep,
  // which does not move those frames, lowered the held-out RMSE by a third).
  double min_fit_gain = 0.005;
  // ... unless delta BIC is below this: very strong in-sample evidence
  // where the current model absorbs most of a small effect in-sample but
  // not out of it (jam_contraction 0.02: RMSE 1.059 -> 1.056 mm, held out
  // 1.509 -> 1.041, delta BIC -487). An effect that does not move the frames
  // cannot lower the BIC by that much.
  double strong_delta_bic = -100.0;
  // ... and it must remove at least this share of the current model's
  // misfit above the noise floor (RMSE^2 - floor^2): an effect that lowers
  // the error significantly but leaves nearly all the misfit is not the
  // one the data miss (an unregistered 5 mm camera bump: area_pressure
  // removed 4 % of it and was chosen).
  double min_excess_share = 0.1;
  // A refitted candidate that passes every test but the held-out one has
  // the folds whose held-out session ends above fold_refit_ratio times its
  // in-sample RMSE there refitted for real (fold_refit.h), the worst first,
  // at most max_fold_refits of them; 0: none.
  double fold_refit_ratio = 1.25;
  int max_fold_refits = 2;
  // Screening (screening.h): a candidate is refitted and cross-validated
  // only if its predicted held-out gain is at least screen_margin *
  // min_heldout_gain and its predicted delta BIC below screen_margin *
  // max_delta_bic (the margin allows for the linearisation's error); the
  // others keep their predicted figures. false: refit every candidate.
  bool screening = true;
  double screen_margin = 0.5;
  // Before screening, each candidate's parameters are scanned coarsely
  // (effect_scan.h); screening and refit start from the best point found.
  bool scan = true;
  // A model the next candidates are judged against (the baseline, a chosen
  // effect) is fitted on from its optimum once more, with a 10x tighter
  // function tolerance, for up to this many times the cap, and one still
  // descending then is probed (optimum_probe.h) and fitted on from a better
  // point; one that still has not converged is reported in
  // Diagnosis::notes. 0: not fitted on.
  int max_continuations = 2;
  // Candidates are refitted in the order of their predicted RMSE (or, where
  // the screening cannot predict, the RMSE at the scan's best point, where
  // the refit starts); one whose figure exceeds this many times the
  // held-out RMSE of a significant candidate already refitted in the round
  // is not refitted (it could not be chosen over it, and its refit costs as
  // much as the baseline fit). 0, or screening off: refit every candidate
  // that passes the screening.
  double refit_cutoff = 2.0;
  // ... and this many times, once that candidate also explains the data
  // (goodness of fit): another can then only tie with it, and one expected
  // far above the noise floor would need its refit to close the whole gap
  // (a small bending: the true effect was expected at 1.17 x the floor, the
  // six others at 1.5-1.7 x, and their refits cost two thirds of the run).
  double refit_cutoff_explained = 1.3;
  EffectScanOptions scan_options;
  // A refitted candidate whose local refit leaves the data unexplained
  // (goodness below) is looked at over each of its parameters' whole
  // ranges: short joint fits from values spanning them (multi_start.h),
  // and if one already beats the local fit, a full refit from there, the
  // better kept. starts = 0: the local refit only.
  MultiStartOptions multi_start{4, 2};
  // ... and probed (optimum_probe.h). Neither search, nor a cell effect's
  // short fits of its best cells (cell_search.h), is paid for where another
  // candidate already leaves search_excess_ratio times less misfit above
  // the noise floor (RMSE^2 - floor^2): a significant one refitted in the
  // round, or for the cells, another effect's scan. 0: always searched.
  double search_excess_ratio = 2.0;
  // At most this many candidates of a round are searched so (the one that
  // leads the round first, then the rest by the lowest RMSE their refit,
  // scan or screening reached): each search costs about a refit.
  int max_basin_searches = 3;
  // The short fits before every such refit instead, from the range and the
  // scan's start (range_start.h), explained or not.
  bool multi_start_before_refit = false;
  // Whether the final model explains the data (goodness_of_fit.h).
  GoodnessOfFitOptions goodness;
  // A candidate whose predicted delta BIC passes but whose predicted
  // held-out gain does not is screened out only if replaying the held-out
  // sessions at the folds' predicted parameters (one replay of the
  // dataset) confirms it (heldout_replayed below).
};

struct CandidateFit {
  std::vector<std::string> effects;  // switched on (beyond the baseline)
  std::string added;                 // the effect this candidate adds
  LeastSquaresResult fit;
  double heldout_rmse_mm = 0.0;
  // Each session's RMSE when held out, and the share of its fold's step
  // taken (cross_validation.h), -1 for a fold refitted for real
  // (fold_refit.h); empty where the figure is a prediction.
  std::vector<double> heldout_session_rmse_mm, fold_step;
  double delta_bic = 0.0;            // against the model it extends
  bool significant = false;
  // Not refitted: fit.params, fit.rmse_mm, heldout_rmse_mm and delta_bic
  // are the screening's predictions, and screening_note says why.
  bool screened_out = false;
  std::string screening_note;
  bool screened = false;  // the screening's predictions below exist
  double predicted_rmse_mm = 0.0, predicted_heldout_rmse_mm = 0.0, predicted_delta_bic = 0.0;
  bool heldout_replayed = false;  // predicted_heldout_rmse_mm is from replayed held-out sessions
  // Where the scan moved the start to, e.g. "bending.kappa_bend 0 -> 0.003
  // (sum of squares -54 %)"; empty if it kept the registry defaults.
  std::string scan_note;
  // Set when the like-with-like recheck (like_with_like.h) changed this
  // candidate's figures: refitted, or no longer significant.
  std::string recheck_note;
  // Set when the refit converged beside a better basin and was restarted
  // from a probed point (optimum_probe.h): where from, and the RMSE gained.
  std::string probe_note;
  std::optional<ModelParams> scanned_start;
  // The multi-start's short fits (multi_start.h), the scan's start last;
  // empty if it did not run.
  std::string multi_start_parameter;
  std::vector<StartTried> starts_tried;
  // The RMSE at the scan's best point (or the start); NaN if not scanned.
  double scan_rmse_mm = std::numeric_limits<double>::quiet_NaN();
};

// Cross-validates c's fit with `parameters`, setting its held-out figures.
void cross_validate_candidate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                              const ReplayOptions& replay, CandidateFit& c);

struct LadderStep {
  std::string label;  // "baseline", "+ bending", ...
  double rmse_mm = 0.0;
  double heldout_rmse_mm = 0.0;
};

struct Diagnosis {
  FitReport baseline;
  double baseline_heldout_rmse_mm = 0.0;
  std::vector<CandidateFit> ranking;  // each candidate on the baseline, best first
  std::vector<CandidateFit> later_rounds;  // candidates tried on top of chosen effects
  std::vector<std::string> verdict;   // chosen effects, in the order added; empty: none needed
  ModelParams final_params;
  std::vector<LadderStep> ladder;
  ResidualPattern pattern;            // of the baseline at its optimum
  std::vector<std::string> skipped;   // candidates that failed to fit, with why
  std::vector<std::string> notes;     // e.g. a model whose fit did not converge
  double noise_floor_mm = 0.0;
  // The final model's residuals against the sensor's noise model: "no
  // effect is needed" only where the baseline passes it.
  GoodnessOfFit goodness;
  // Where the final model's residual concentrates (the baseline's pattern
  // when nothing was chosen).
  ResidualPattern final_pattern;
  // Where the missing effect is, worst first: the cell of a chosen local
  // effect (cell_defect), then the baseline residual's worst cells.
  std::vector<std::pair<int, int>> worst_cells;
  // The lowest in-sample RMSE any refitted model reached, and its effects.
  double best_rmse_mm = 0.0;
  std::vector<std::string> best_effects;
};

// BIC of a least-squares fit with Gaussian residuals: n ln(SSR / n) + p ln n.
double bic(const LeastSquaresResult& fit);

// The RMSE a perfect model leaves: the sensor's accuracy taken as its noise
// sigma, plus the rounding to its resolution (res^2 / 12).
double noise_floor_mm(const Dataset& dataset);

using DiagnoseProgress = std::function<void(const std::string& stage, int done, int total, const std::string& detail)>;

Diagnosis diagnose(const Dataset& dataset, const ModelParams& start, const DiagnoseOptions& options,
                   const DiagnoseProgress& progress = {});

}  // namespace hj
