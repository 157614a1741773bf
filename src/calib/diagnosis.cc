#include "calib/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "calib/candidate_refit.h"
#include "calib/candidate_screening.h"
#include "calib/cell_search.h"
#include "calib/final_model.h"
#include "calib/gain_by_capture.h"
#include "calib/goodness_of_fit.h"
#include "calib/like_with_like.h"
#include "calib/range_start.h"
#include "calib/redundant_effects.h"

namespace hj {

namespace {

std::vector<std::string> candidate_effects(const DiagnoseOptions& options) {
  if (!options.candidates.empty()) return options.candidates;
  std::vector<std::string> out;
  for (const auto& name : EffectRegistry::instance().names())
    if (!EffectRegistry::instance().get(name).baseline) out.push_back(name);
  return out;
}

// Fits `fit` on from where it stopped, restarting Ceres once with a tighter
// tolerance (see DiagnoseOptions::max_continuations), then, if it is still
// descending at that cap, from the best point of an optimum probe; says so
// in notes if it does not converge. True if the fit moved on.
// Without it, a candidate refitted from an optimum the cap cut short gets
// further down the same valley and is credited with it: on a synthetic
// camera tilt, jam_creep, which cannot change those frames, lowered the
// held-out error by 10 % in the round after sensor_tilt was chosen.
bool converge(const Dataset& dataset, const std::vector<FitParameter>& parameters, const DiagnoseOptions& options,
              const std::string& label, const DiagnoseProgress& progress, LeastSquaresResult& fit,
              std::vector<std::string>& notes) {
  const int cap = options.fit.least_squares.max_iterations;
  const int more = cap * options.max_continuations;  // one restart: it resets Ceres' trust region
  bool moved = false;
  if (more > 0) {
    // Also when Ceres said it converged: its relative function tolerance
    // can stop a fit in a long shallow valley (synthetic bending: stopped
    // at 1.49 mm held out, where every next candidate's refit went on to
    // 1.04 and looked significant). A restart with a tighter tolerance
    // costs a Jacobian or two where the fit really is done.
    const std::string stage = "converging " + label;
    LeastSquaresOptions longer = options.fit.least_squares;
    longer.max_iterations = more;
    longer.function_tolerance *= 0.1;
    LeastSquaresResult next =
        fit_least_squares(dataset, fit.params, parameters, longer, least_squares_progress(progress, stage));
    if (next.sum_sq_mm2 <= fit.sum_sq_mm2) {  // it starts at the fit's optimum: never worse
      next.iterations += fit.iterations;
      fit = std::move(next);
      moved = true;
    }
  }
  if (more > 0 && fit.stopped_at_cap) {
    // Still descending after the continuation: a probe may find the point
    // far down its valley (one more way of fitting on, so off with them).
    const double before = fit.sum_sq_mm2;
    fit = probe_and_refit(dataset, parameters, options.fit, progress, std::move(fit), notes);
    moved = moved || fit.sum_sq_mm2 < before;
  }
  if (!fit.converged) {
    char note[400];
    std::snprintf(note, sizeof note,
                  "%s: the fit did not converge within %d iterations (RMSE %.4f mm); later candidates are judged "
                  "against an unfinished fit",
                  label.c_str(), cap + more, fit.rmse_mm);
    notes.push_back(note);
  }
  return moved;
}

}  // namespace

bool ranks_before(const CandidateFit& a, const CandidateFit& b) {
  if (a.significant != b.significant) return a.significant;
  if (a.significant) return a.delta_bic < b.delta_bic;
  return a.heldout_rmse_mm < b.heldout_rmse_mm;
}

void cross_validate_candidate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                              const ReplayOptions& replay, CandidateFit& c) {
  CrossValidation cv = cross_validate(dataset, parameters, c.fit, replay);
  c.heldout_rmse_mm = cv.heldout_rmse_mm;
  c.heldout_session_rmse_mm = std::move(cv.session_rmse_mm);
  c.fold_step = std::move(cv.fold_step);
}

namespace {

void rank(std::vector<CandidateFit>& fits) { std::stable_sort(fits.begin(), fits.end(), ranks_before); }

// Replaces `current` (and its held-out RMSE, the ladder's last step, and
// in round 0 the baseline) by the current model refitted from `c`'s
// optimum with c's effect off, if that fits better (like_with_like.h); true
// if it did. Says so in out.notes either way once it refits.
bool recheck_current(const Dataset& dataset, const DiagnoseOptions& options, int round, const CandidateFit& c,
                     const std::vector<std::string>& chosen, const DiagnoseProgress& progress, Diagnosis& out,
                     LeastSquaresResult& current, double& current_heldout) {
  std::string label = "baseline";
  for (const auto& e : chosen) label += " + " + e;
  const std::string stage = "recheck " + label + " from " + c.added + "'s optimum";
  const auto parameters = fit_parameters(chosen);
  if (progress) progress(stage, 0, options.fit.least_squares.max_iterations, "");
  LikeWithLike check = refit_from_candidate_optimum(
      dataset, current, parameters, c.fit.params, c.added, options.min_fit_gain, options.fit.least_squares,
      least_squares_progress(progress, stage));
  if (!check.refit) {
    if (progress)
      progress(stage, options.fit.least_squares.max_iterations, options.fit.least_squares.max_iterations,
               "not needed");
    return false;
  }
  LeastSquaresResult& refit = *check.refit;
  converge(dataset, parameters, options, label + " (refitted from " + c.added + "'s optimum)", progress, refit,
           out.notes);
  char note[400];
  const bool better = refit.sum_sq_mm2 < current.sum_sq_mm2;
  std::snprintf(note, sizeof note,
                "%s at %s's optimum with %s off replays at %.4f mm, below its own fit's %.4f mm: refitted from "
                "there it reaches %.4f mm%s",
                label.c_str(), c.added.c_str(), c.added.c_str(), check.stripped_rmse_mm, current.rmse_mm,
                refit.rmse_mm, better ? ", and the candidates are judged against that fit" : ", no better: kept");
  out.notes.push_back(note);
  if (!better) return false;
  current = std::move(refit);
  if (progress) progress("cross-validation", 0, 1, label);
  const CrossValidation cv = cross_validate(dataset, parameters, current, options.fit.least_squares.replay);
  current_heldout = cv.heldout_rmse_mm;
  if (progress) progress("cross-validation", 1, 1, label);
  out.ladder.back().rmse_mm = current.rmse_mm;
  out.ladder.back().heldout_rmse_mm = current_heldout;
  if (round == 0) {
    out.baseline.joint = current;
    out.baseline_heldout_rmse_mm = current_heldout;
    out.pattern = describe_residuals(dataset, evaluate_dataset(dataset, current.params, options.fit.least_squares.replay));
  } else {
    // The record of the candidate the current model is (chosen is its
    // effects; no other candidate has exactly those).
    for (auto* record : {&out.ranking, &out.later_rounds})
      for (CandidateFit& chosen_fit : *record)
        if (chosen_fit.effects == chosen) {
          chosen_fit.delta_bic += bic(current) - bic(chosen_fit.fit);
          chosen_fit.fit = current;
          chosen_fit.heldout_rmse_mm = current_heldout;
          chosen_fit.heldout_session_rmse_mm = cv.session_rmse_mm;
          chosen_fit.fold_step = cv.fold_step;
          chosen_fit.recheck_note = "refitted from " + c.added + "'s optimum with " + c.added + " off";
        }
  }
  return true;
}

// Says so in notes where most of a chosen effect's fall in the sum of
// squares is in one capture (gain_by_capture.h): the user should look at
// that capture before trusting the effect.
void note_gain_in_one_capture(const Dataset& dataset, const LeastSquaresResult& current, const CandidateFit& best,
                              std::vector<std::string>& notes) {
  if (best.fit.residuals.size() != current.residuals.size() || current.residuals.size() == 0) return;
  CaptureGain gain;
  try {
    gain = largest_capture_gain(dataset, current.residuals, best.fit.residuals);
  } catch (const std::invalid_argument&) {
    return;  // not laid out per capture: nothing to say
  }
  if (gain.capture < 0 || !(gain.share > 0.5) || dataset.capture_count() < 3) return;
  char note[400];
  std::snprintf(note, sizeof note,
                "%s: %.0f %% of its fall in the sum of squares is in one capture, %s (RMSE %.3f -> %.3f mm); a gain "
                "that rests on one capture may be the model's sensitivity there (near the levelling pressure, or a "
                "jammed shape near a limit point) rather than the effect",
                best.added.c_str(), 100.0 * std::min(gain.share, 1.0),
                capture_name(dataset, gain.session, gain.capture).c_str(), gain.before_rmse_mm, gain.after_rmse_mm);
  notes.push_back(note);
}

// The baseline, fitted the paper's way then jointly, its held-out RMSE, the
// ladder's first step and where its residual concentrates.
void fit_baseline(const Dataset& dataset, const ModelParams& start, const DiagnoseOptions& options,
                  const DiagnoseProgress& progress, Diagnosis& out) {
  const ReplayOptions& replay = options.fit.least_squares.replay;
  ModelParams base_start = start;
  base_start.effects.clear();
  base_start.effect_parameters.clear();
  out.baseline = fit_model(dataset, base_start, {}, options.fit, progress);
  for (const std::string& n : out.baseline.probe_notes) out.notes.push_back("baseline: " + n);
  const auto base_parameters = fit_parameters({});
  converge(dataset, base_parameters, options, "baseline", progress, out.baseline.joint, out.notes);
  if (progress) progress("cross-validation", 0, 1, "baseline");
  out.baseline_heldout_rmse_mm = cross_validate(dataset, base_parameters, out.baseline.joint, replay).heldout_rmse_mm;
  if (progress) progress("cross-validation", 1, 1, "baseline");
  out.ladder.push_back({"baseline", out.baseline.joint.rmse_mm, out.baseline_heldout_rmse_mm});
  if (progress) progress("residual pattern", 0, 1, "");
  out.pattern = describe_residuals(dataset, evaluate_dataset(dataset, out.baseline.joint.params, replay));
  if (progress) progress("residual pattern", 1, 1, "");
}

// The candidate that adds `effect` to the chosen ones, its start moved by
// the scan (effect_scan.h) where that found a better one; a cell effect's
// search fits its best cells only where it predicts a sum of squares below
// `refine_below` (cell_search.h).
CandidateFit scanned_candidate(const Selection& s, const std::string& effect, double refine_below) {
  CandidateFit c;
  c.effects = s.chosen;
  c.effects.push_back(effect);
  c.added = effect;
  if (!s.options.scan) return c;
  const auto parameters = fit_parameters(c.effects);
  if (s.progress) s.progress("scan " + effect, 0, 1, "");
  try {
    ModelParams start = with_effects(s.current.params, c.effects);
    if (is_cell_effect(effect)) {
      // Which cell: a search no local fit can make (cell_search.h).
      CellSearch cell =
          search_cells(s.dataset, start, parameters, effect, s.current, s.options.fit.least_squares, refine_below);
      start = cell.best;
      c.scanned_start = start;
      c.scan_note = cell.note;
    }
    EffectScan scan = scan_effect_start(s.dataset, start, parameters, effect, s.options.fit.least_squares.replay,
                                        s.options.scan_options);
    c.scan_rmse_mm = std::sqrt(scan.best_sum_sq_mm2 / std::max(s.current.residual_count, 1L));
    if (scan.moved) {
      c.scanned_start = std::move(scan.best);
      c.scan_note += (c.scan_note.empty() ? "" : "; ") + scan.note;
    }
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    // The defaults do not replay: the starts below say what does.
  }
  if (s.progress) s.progress("scan " + effect, 1, 1, c.scan_note);
  return c;
}

// The sum of squares under which a cell effect's best cells are fitted:
// the one that leaves search_excess_ratio times the misfit above the floor
// that the best scan so far (`best_scan_sum_sq`) leaves.
double refine_cells_below(const Selection& s, double best_scan_sum_sq) {
  const double ratio = s.options.search_excess_ratio;
  if (!(ratio > 0.0) || !std::isfinite(best_scan_sum_sq)) return std::numeric_limits<double>::infinity();
  const double n = static_cast<double>(std::max(s.current.residual_count, 1L));
  const double floor_sum_sq = n * s.out.noise_floor_mm * s.out.noise_floor_mm;
  return floor_sum_sq + ratio * std::max(0.0, best_scan_sum_sq - floor_sum_sq);
}

// Scans and screens each remaining effect: those the screening keeps out go
// to `fits` with their predicted figures, the others to `to_refit`. The
// cell effects go last: their search's short fits, the dearest part of a
// scan, are paid for only where no other effect's scan already left
// search_excess_ratio times less misfit above the floor (a strong bending:
// -80 % against a cell's -4 %, 160 of 720 CPU s in two rounds).
void scan_and_screen(const Selection& s, std::vector<std::string> remaining, std::vector<CandidateFit>& fits,
                     std::vector<CandidateFit>& to_refit) {
  std::stable_partition(remaining.begin(), remaining.end(), [](const std::string& e) { return !is_cell_effect(e); });
  double best_scan_sum_sq = std::numeric_limits<double>::infinity();
  for (const auto& effect : remaining) {
    const double refine_below = refine_cells_below(s, best_scan_sum_sq);
    CandidateFit c = scanned_candidate(s, effect, refine_below);
    if (std::isfinite(c.scan_rmse_mm))
      best_scan_sum_sq = std::min(best_scan_sum_sq, c.scan_rmse_mm * c.scan_rmse_mm * s.current.residual_count);
    if (s.options.screening) {
      const auto parameters = fit_parameters(c.effects);
      if (s.progress) s.progress("screening " + effect, 0, 1, "");
      const bool out_of_the_running = screen_out(s.dataset, s.current, s.current_heldout, parameters, s.options, c);
      if (s.progress) s.progress("screening " + effect, 1, 1, out_of_the_running ? "screened out" : "refit");
      if (out_of_the_running) {
        fits.push_back(std::move(c));
        continue;
      }
    }
    to_refit.push_back(std::move(c));
  }
}

// Like with like (like_with_like.h): a candidate's optimum with its effect
// switched off may fit better than the current model's own optimum; then
// the current model is refitted from there and every candidate judged
// against that. Each refitted candidate that lowered the in-sample RMSE by
// min_fit_gain is checked (one replay), the lowest first, significant or
// not; two refits at most a round.
void recheck_like_with_like(Selection& s, int round, std::vector<CandidateFit>& fits) {
  std::vector<std::string> rechecked;
  for (int refits = 0; refits < 2;) {
    const CandidateFit* next = nullptr;
    for (const CandidateFit& c : fits)
      if (!c.screened_out && c.fit.rmse_mm <= (1.0 - s.options.min_fit_gain) * s.current.rmse_mm &&
          std::find(rechecked.begin(), rechecked.end(), c.added) == rechecked.end() &&
          (!next || c.fit.rmse_mm < next->fit.rmse_mm))
        next = &c;
    if (!next) break;
    rechecked.push_back(next->added);
    if (!recheck_current(s.dataset, s.options, round, *next, s.chosen, s.progress, s.out, s.current,
                         s.current_heldout))
      continue;
    ++refits;
    const std::string why = "not significant against the current model refitted from " + next->added + "'s optimum";
    // Every refitted candidate's delta BIC is against the model it extends,
    // so against this fit now. One that fits worse than it stopped short
    // and is refitted from it; any other that was not significant cannot
    // become so against a better fit.
    for (CandidateFit& c : fits) {
      if (c.screened_out) continue;  // predicted figures: kept as predicted
      const bool refitted = c.fit.sum_sq_mm2 > s.current.sum_sq_mm2 && refit_from_rebased_current(s, c);
      c.delta_bic = bic(c.fit) - bic(s.current);
      if (!refitted && !c.significant) continue;
      c.significant = is_significant(c, s);
      if (!refitted && !c.significant) c.recheck_note = why;
    }
    rank(fits);
  }
}

// The round's choice, fits.front() if significant: the next round is judged
// against its fit, so it must have converged (the ranking shows it so, as
// the final parameters are). False if the round chose nothing.
bool converge_choice(Selection& s, std::vector<CandidateFit>& fits) {
  if (fits.empty() || !fits.front().significant) return false;
  CandidateFit& best = fits.front();
  std::string label = "baseline";
  for (const auto& e : best.effects) label += " + " + e;
  const auto best_parameters = fit_parameters(best.effects);
  if (converge(s.dataset, best_parameters, s.options, label, s.progress, best.fit, s.out.notes)) {
    const std::vector<double> steps_before = best.fold_step;
    cross_validate_candidate(s.dataset, best_parameters, s.options.fit.least_squares.replay, best);
    // A fold its judgement refitted for real is refitted again from the new optimum.
    for (size_t k = 0; k < steps_before.size() && k < best.fold_step.size(); ++k)
      if (steps_before[k] < 0.0) refit_fold_of(s, best_parameters, static_cast<int>(k), best);
    best.delta_bic = bic(best.fit) - bic(s.current);
  }
  note_gain_in_one_capture(s.dataset, s.current, best, s.out.notes);
  return true;
}

// The effects later rounds try: those that lowered the held-out error in
// this round, and those screened out only by their replayed held-out
// sessions while their predicted BIC passed. That held-out replay is one
// Gauss-Newton step from a model that may have absorbed the other effect in
// the data into distorted parameters, so it is judged again against the
// next, better model (a strong stiffening with a camera tilt: the tilt's
// held-out error rose 27 % against the baseline, and it was never tried on
// top of stiffening).
std::vector<std::string> effects_for_next_round(const std::vector<CandidateFit>& fits, const CandidateFit& best,
                                                double current_heldout) {
  std::vector<std::string> next;
  for (const auto& c : fits)
    if (c.added != best.added && (c.heldout_rmse_mm < current_heldout || (c.screened_out && c.heldout_replayed)))
      next.push_back(c.added);
  return next;
}

// The optima of the significant candidates not chosen (fits.front() is),
// starts for their searches in later rounds.
void remember_earlier_optima(const std::vector<CandidateFit>& fits, Selection& s) {
  for (size_t k = 1; k < fits.size(); ++k)
    if (fits[k].significant && !fits[k].screened_out) s.earlier_optima[fits[k].added] = fits[k].fit.params;
}

// The chosen model's residuals pass the chi-square test against the
// sensor's noise itself (not only the floor's tolerance): no further effect
// can lower the held-out error by a real margin, so no round is run for one.
bool leaves_only_noise(const Selection& s) {
  const GoodnessOfFit g = goodness_of_fit(s.current, s.out.noise_floor_mm, s.options.goodness);
  if (g.p_value < s.options.goodness.alpha) return false;
  char note[200];
  std::snprintf(note, sizeof note,
                "no further round: with %s the residuals are the sensor's noise (chi-square p = %.3g)",
                s.chosen.back().c_str(), g.p_value);
  s.out.notes.push_back(note);
  return true;
}

}  // namespace

double bic(const LeastSquaresResult& fit) {
  const double n = static_cast<double>(fit.residual_count);
  return n * std::log(std::max(fit.sum_sq_mm2, 1e-300) / n) + fit.free_parameters * std::log(n);
}

double noise_floor_mm(const Dataset& dataset) {
  const Session& s = dataset.sessions.front().session;
  return std::sqrt(s.sensor_accuracy_mm * s.sensor_accuracy_mm +
                   s.sensor_resolution_mm * s.sensor_resolution_mm / 12.0);
}

Diagnosis diagnose(const Dataset& dataset, const ModelParams& start, const DiagnoseOptions& options,
                   const DiagnoseProgress& progress) {
  Diagnosis out;
  out.noise_floor_mm = noise_floor_mm(dataset);
  fit_baseline(dataset, start, options, progress, out);
  // Greedy forward selection: each round adds the significant candidate
  // with the lowest delta BIC to the current model (ranks_before).
  Selection s{dataset, options, progress, out, {}, out.baseline.joint, out.baseline_heldout_rmse_mm};
  std::vector<std::string> remaining = candidate_effects(options);
  for (int round = 0; round < options.max_effects && !remaining.empty(); ++round) {
    std::vector<CandidateFit> fits, to_refit;
    scan_and_screen(s, remaining, fits, to_refit);
    refit_candidates(s, to_refit, fits);
    rank(fits);
    recheck_like_with_like(s, round, fits);
    const bool chosen_one = converge_choice(s, fits);
    auto& record = round == 0 ? out.ranking : out.later_rounds;
    record.insert(record.end(), fits.begin(), fits.end());
    if (!chosen_one) break;
    const CandidateFit& best = fits.front();
    remember_earlier_optima(fits, s);
    remaining = effects_for_next_round(fits, best, s.current_heldout);
    s.chosen.push_back(best.added);
    s.current = best.fit;
    s.current_heldout = best.heldout_rmse_mm;
    out.ladder.push_back({"+ " + best.added, best.fit.rmse_mm, best.heldout_rmse_mm});
    if (leaves_only_noise(s)) break;
  }
  drop_redundant_effects(s);
  out.verdict = s.chosen;
  out.final_params = s.current.params;
  judge_final_model(dataset, options, s.current, out);
  return out;
}

}  // namespace hj
