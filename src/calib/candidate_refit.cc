#include "calib/candidate_refit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "calib/candidate_screening.h"
#include "calib/fold_refit.h"
#include "calib/goodness_of_fit.h"
#include "calib/range_start.h"

namespace hj {

double excess_mm2(const LeastSquaresResult& fit, const Selection& s) {
  const double floor = s.out.noise_floor_mm;
  return std::max(0.0, fit.rmse_mm * fit.rmse_mm - floor * floor);
}

double excess_share_removed(const CandidateFit& c, const Selection& s) {
  const double excess = excess_mm2(s.current, s);
  if (!(excess > 0.0)) return 1.0;
  return (s.current.rmse_mm * s.current.rmse_mm - c.fit.rmse_mm * c.fit.rmse_mm) / excess;
}

SignificanceTests significance_tests(const CandidateFit& c, const Selection& s) {
  const DiagnoseOptions& options = s.options;
  SignificanceTests t;
  t.heldout = c.heldout_rmse_mm <= (1.0 - options.min_heldout_gain) * s.current_heldout;
  t.bic = c.delta_bic < options.max_delta_bic;
  t.fit = c.fit.rmse_mm <= (1.0 - options.min_fit_gain) * s.current.rmse_mm || c.delta_bic < options.strong_delta_bic;
  t.material = excess_share_removed(c, s) >= options.min_excess_share;
  return t;
}

bool is_significant(const CandidateFit& c, const Selection& s) {
  return significance_tests(c, s).all();
}

bool worth_a_basin_search(const Selection& s, const CandidateFit& c, bool strict) {
  const GoodnessOfFit g = goodness_of_fit(c.fit, s.out.noise_floor_mm, s.options.goodness);
  if (s.round_explained || (strict ? g.p_value >= s.options.goodness.alpha : g.explained)) return false;
  const double ratio = s.options.search_excess_ratio;
  return !(ratio > 0.0 && excess_mm2(c.fit, s) > ratio * s.round_best_excess_mm2);
}

void refit_fold_of(Selection& s, const std::vector<FitParameter>& parameters, int k, CandidateFit& c) {
  const std::string& name = s.dataset.sessions[k].session.name;
  if (s.progress) s.progress("fold refit " + c.added, 0, 1, name);
  const FoldRefit fold = refit_fold(s.dataset, parameters, c.fit, k, s.options.fit.least_squares);
  if (s.progress) s.progress("fold refit " + c.added, 1, 1, name);
  char note[300];
  std::snprintf(note, sizeof note, "%s: session %s held out is %.3f mm after its fold's one step, %.3f mm refitted without it",
                c.added.c_str(), name.c_str(), c.heldout_session_rmse_mm[k], fold.heldout_rmse_mm);
  s.out.notes.push_back(note);
  c.heldout_session_rmse_mm[k] = fold.heldout_rmse_mm;
  c.fold_step[k] = -1.0;  // refitted, not stepped
  c.heldout_rmse_mm = pooled_heldout_rmse(c.heldout_session_rmse_mm, c.fit.session_rows);
}

namespace {

LeastSquaresResult fit_candidate(const Dataset& dataset, const ModelParams& current, const CandidateFit& c,
                                 const std::vector<FitParameter>& parameters, const DiagnoseOptions& options,
                                 const LeastSquaresProgress& progress) {
  const std::vector<ModelParams> starts = candidate_starts(c, current, parameters);
  for (size_t k = 0;; ++k) {
    try {
      return fit_least_squares(dataset, starts[k], parameters, options.fit.least_squares, progress);
    } catch (const SettleInterrupted&) {
      throw;  // the caller stopped the work: not a failed replay
    } catch (const std::exception&) {
      if (k + 1 == starts.size()) throw;
    }
  }
}

// What a candidate's refit is expected to reach: the screening's predicted
// RMSE, or where its linearisation says nothing (a start far from neutral),
// the RMSE at the scan's best point, where the refit starts; infinity if
// neither is known (then it is refitted last, and always).
double expected_rmse(const CandidateFit& c) {
  if (c.screened) return c.predicted_rmse_mm;
  return std::isfinite(c.scan_rmse_mm) ? c.scan_rmse_mm : std::numeric_limits<double>::infinity();
}

// A candidate not refitted because the RMSE its refit is expected to reach
// is more than refit_cutoff (refit_cutoff_explained once one explains the
// data) times the held-out RMSE of a significant one already refitted in
// this round: it keeps the expected figures and a note, as a screened-out
// candidate does.
void outrun(CandidateFit& c, const LeastSquaresResult& current, double best_heldout, const std::string& best) {
  const double expected = expected_rmse(c);
  c.fit = LeastSquaresResult{};
  c.fit.params = c.scanned_start ? *c.scanned_start : with_effects(current.params, c.effects);
  c.fit.rmse_mm = expected;
  c.heldout_rmse_mm = c.screened ? c.predicted_heldout_rmse_mm : expected;
  c.delta_bic = c.screened ? c.predicted_delta_bic : std::numeric_limits<double>::quiet_NaN();
  c.significant = false;
  c.screened_out = true;
  char note[240];
  std::snprintf(note, sizeof note,
                "not refitted: its %s RMSE %.3f mm cannot come near %s's refitted held-out RMSE %.3f mm",
                c.screened ? "predicted" : "scanned", expected, best.c_str(), best_heldout);
  c.screening_note = note;
}

// A local refit that leaves the data unexplained may have stopped in the
// basin the current model's distorted optimum put it in (a strong effect
// the baseline absorbed): where a short fit from the new parameter's range
// already beats it, the candidate is refitted in full from there and the
// better fit kept. Only where worth_a_basin_search (selection.h).
void refit_over_range_if_unexplained(const Selection& s, const std::vector<FitParameter>& parameters,
                                     const LeastSquaresProgress& progress, CandidateFit& c) {
  if (!worth_a_basin_search(s, c)) return;
  const std::optional<ModelParams> start = better_start_than_local(s.dataset, c.fit, s.options, s.progress, c);
  if (!start) return;
  CandidateFit from_range = c;
  from_range.scanned_start = *start;
  LeastSquaresResult again = fit_candidate(s.dataset, s.current.params, from_range, parameters, s.options, progress);
  if (again.sum_sq_mm2 < c.fit.sum_sq_mm2) {
    c.fit = std::move(again);
    c.scanned_start = *start;
  }
}

// A local refit that converged with the data unexplained may sit beside a
// better basin: the cost has kinks where a jammed capture switches shape
// (on a small bending, 0.0005 N m/rad, the refit stopped at its scan's
// start, 0.001, RMSE 1.39 mm, with the truth's basin at 1.04). It is probed
// as a fit's optimum is (optimum_probe.h), and refitted from a better point.
void probe_if_unexplained(const Selection& s, const std::vector<FitParameter>& parameters, const std::string& stage,
                          CandidateFit& c) {
  if (!worth_a_basin_search(s, c)) return;
  const FitProgress progress = [&](const std::string& step, int done, int total, const std::string& detail) {
    if (s.progress) s.progress(stage + ": " + step, done, total, detail);
  };
  std::vector<std::string> notes;
  c.fit = probe_and_refit(s.dataset, parameters, s.options.fit, progress, std::move(c.fit), notes);
  for (const std::string& note : notes) c.probe_note += (c.probe_note.empty() ? "" : "; ") + note;
}

// A candidate significant and not chosen in an earlier round is refitted
// from its own optimum there (the chosen effects as the current model has
// them): two effects that each absorbed part of the data into the baseline
// differently may meet only from there (jam_contraction's fit took the mass
// to 0.43 kg for a pressure offset it lacked, the offset's own fit had 0.51
// kg and 43 Pa, the truth 0.52 kg and 40 Pa). The better fit is kept.
void refit_from_earlier_optimum(const Selection& s, const std::vector<FitParameter>& parameters,
                                const std::string& stage, CandidateFit& c) {
  const auto earlier = s.earlier_optima.find(c.added);
  if (earlier == s.earlier_optima.end()) return;
  ModelParams start = with_effects(s.current.params, c.effects);
  start.surface = earlier->second.surface;
  start.effect_parameters[c.added] = earlier->second.effect_parameters.at(c.added);
  LeastSquaresResult again = fit_least_squares(s.dataset, start, parameters, s.options.fit.least_squares,
                                               least_squares_progress(s.progress, stage + " from its earlier optimum"));
  if (!(again.sum_sq_mm2 < c.fit.sum_sq_mm2)) return;
  char note[200];
  std::snprintf(note, sizeof note, "refitted from its optimum of an earlier round: RMSE %.4f -> %.4f mm",
                c.fit.rmse_mm, again.rmse_mm);
  c.probe_note += (c.probe_note.empty() ? "" : "; ") + std::string(note);
  c.fit = std::move(again);
}

// Says so in notes where a candidate passes every test except the share of
// the misfit above the floor it removes: the user sees it was weighed.
void note_if_immaterial(Selection& s, const CandidateFit& c) {
  if (!significance_tests(c, s).only_material_fails()) return;
  char note[300];
  std::snprintf(note, sizeof note,
                "%s lowers the error (RMSE %.4f -> %.4f mm) but removes only %.0f %% of the misfit above the noise "
                "floor (needs %.0f %%): not chosen, the effect in the data is another",
                c.added.c_str(), s.current.rmse_mm, c.fit.rmse_mm, 100.0 * excess_share_removed(c, s),
                100.0 * s.options.min_excess_share);
  s.out.notes.push_back(note);
}

// A candidate refused only by its held-out error: the folds whose held-out
// session ends clearly above the candidate's in-sample error there are
// refitted for real (fold_refit.h), the worst first, until it passes, at
// most max_fold_refits of them. Says so in notes.
void refit_deciding_folds(Selection& s, const std::vector<FitParameter>& parameters, CandidateFit& c) {
  if (!significance_tests(c, s).only_heldout_fails()) return;
  const std::vector<int>& rows = c.fit.session_rows;
  const int sessions = static_cast<int>(c.heldout_session_rmse_mm.size());
  if (static_cast<int>(rows.size()) != sessions + 1 || c.fit.residuals.size() != rows.back()) return;
  std::vector<std::pair<double, int>> worst;  // held-out over in-sample RMSE, session
  for (int k = 0; k < sessions; ++k) {
    const int n = rows[k + 1] - rows[k];
    if (n == 0) continue;
    const double in_sample = std::sqrt(c.fit.residuals.segment(rows[k], n).squaredNorm() / n);
    const double ratio = c.heldout_session_rmse_mm[k] / std::max(in_sample, 1e-9);
    if (ratio > s.options.fold_refit_ratio) worst.emplace_back(ratio, k);
  }
  std::sort(worst.rbegin(), worst.rend());
  if (static_cast<int>(worst.size()) > s.options.max_fold_refits) worst.resize(s.options.max_fold_refits);
  for (const auto& [ratio, k] : worst) {
    refit_fold_of(s, parameters, k, c);
    if (significance_tests(c, s).heldout) break;
  }
}

// Cross-validates c's fit and judges it against the current model.
void judge(Selection& s, const std::vector<FitParameter>& parameters, CandidateFit& c) {
  if (s.progress) s.progress("cross-validation", 0, 1, c.added);
  cross_validate_candidate(s.dataset, parameters, s.options.fit.least_squares.replay, c);
  c.delta_bic = bic(c.fit) - bic(s.current);
  refit_deciding_folds(s, parameters, c);
  c.significant = is_significant(c, s);
}

// One progress stage per candidate, so that its time shows apart.
std::string stage_of(const Selection& s, const CandidateFit& c) {
  std::string on;
  for (const auto& e : s.chosen) on += " + " + e;
  return "candidate " + c.added + (on.empty() ? "" : " on baseline" + on);
}

void report_done(const Selection& s, const CandidateFit& c) {
  const int cap = s.options.fit.least_squares.max_iterations;
  if (s.progress) s.progress(stage_of(s, c), cap, cap, "held out " + std::to_string(c.heldout_rmse_mm) + " mm");
}

// Refits one candidate from the current optimum (or where the scan or the
// short fits over its range found it best), cross-validates it and judges
// it; false (and said so in out.skipped) if the model cannot replay it.
bool refit_locally(Selection& s, CandidateFit& c) {
  const auto parameters = fit_parameters(c.effects);
  const std::string stage = stage_of(s, c);
  try {
    if (s.options.multi_start_before_refit) start_from_best_of_range(s.dataset, s.current.params, s.options, s.progress, c);
    c.fit = fit_candidate(s.dataset, s.current.params, c, parameters, s.options, least_squares_progress(s.progress, stage));
    judge(s, parameters, c);
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception& e) {
    s.out.skipped.push_back(c.added + ": " + e.what());
    return false;
  }
  report_done(s, c);
  return true;
}

// Searches a locally refitted candidate for a better basin where that is
// worth it (worth_a_basin_search), and judges it again if one is found; a
// search the model cannot replay leaves the local refit as it was. True if
// it searched.
bool search_for_a_better_basin(Selection& s, CandidateFit& c) {
  const bool from_earlier = s.earlier_optima.count(c.added) > 0;
  if (!worth_a_basin_search(s, c, from_earlier)) return false;
  const auto parameters = fit_parameters(c.effects);
  const std::string stage = stage_of(s, c);
  CandidateFit searched = c;
  try {
    if (from_earlier) refit_from_earlier_optimum(s, parameters, stage, searched);
    if (!s.options.multi_start_before_refit)
      refit_over_range_if_unexplained(s, parameters, least_squares_progress(s.progress, stage), searched);
    probe_if_unexplained(s, parameters, stage, searched);
    if (!(searched.fit.sum_sq_mm2 < c.fit.sum_sq_mm2)) {
      searched.fit = std::move(c.fit);  // the local refit and its judgement stand; the starts tried are kept
      c = std::move(searched);
      return true;
    }
    judge(s, parameters, searched);
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    return true;  // the local refit stands
  }
  c = std::move(searched);
  report_done(s, c);
  return true;
}

// The lowest RMSE a candidate is known to reach: its local refit's, or
// where the screening or the scan saw lower (a strong effect whose local
// refit stayed in the current model's basin), that.
double evidence_rmse(const CandidateFit& c) { return std::min(c.fit.rmse_mm, expected_rmse(c)); }

// The round's bookkeeping beside Selection's: the best held-out RMSE of a
// significant candidate and its name (the refit cutoff), and the searches
// for a better basin spent.
struct RoundTally {
  double best_heldout = std::numeric_limits<double>::infinity();
  std::string best;
  int searches = 0;
};

// The round's state after c was judged: whether a significant candidate
// explains the data, the least misfit one leaves, the best held-out RMSE.
void note_in_round(Selection& s, const CandidateFit& c, RoundTally& round) {
  if (!c.significant) return;
  if (goodness_of_fit(c.fit, s.out.noise_floor_mm, s.options.goodness).explained) s.round_explained = true;
  s.round_best_excess_mm2 = std::min(s.round_best_excess_mm2, excess_mm2(c.fit, s));
  if (c.heldout_rmse_mm < round.best_heldout) round.best_heldout = c.heldout_rmse_mm, round.best = c.added;
}

// Refits each candidate locally, the most promising first, unless the
// refit cutoff rules it out (then it goes to `fits` with its expected
// figures); the one that leads the round is searched at once, since its
// result sets the cutoff for the rest. Returns the refitted ones, and in
// `searched` whether each was searched.
std::vector<CandidateFit> refit_each_locally(Selection& s, std::vector<CandidateFit>& to_refit,
                                             std::vector<CandidateFit>& fits, RoundTally& round,
                                             std::vector<char>& searched) {
  std::stable_sort(to_refit.begin(), to_refit.end(), [](const CandidateFit& a, const CandidateFit& b) {
    return expected_rmse(a) < expected_rmse(b);
  });
  std::vector<CandidateFit> refitted;
  for (CandidateFit& c : to_refit) {
    const double cutoff = s.round_explained ? s.options.refit_cutoff_explained : s.options.refit_cutoff;
    if (s.options.screening && s.options.refit_cutoff > 0.0 && expected_rmse(c) > cutoff * round.best_heldout) {
      outrun(c, s.current, round.best_heldout, round.best);
      fits.push_back(std::move(c));
      continue;
    }
    if (!refit_locally(s, c)) continue;
    const bool leads = c.significant && excess_mm2(c.fit, s) < s.round_best_excess_mm2;
    const bool now = leads && round.searches < s.options.max_basin_searches && search_for_a_better_basin(s, c);
    round.searches += now;
    note_in_round(s, c, round);
    refitted.push_back(std::move(c));
    searched.push_back(now);
  }
  return refitted;
}

// Searches the refitted candidates not searched yet, those significant in
// an earlier round first (they have shown they can help), then the best
// evidence, until max_basin_searches are spent.
void search_the_rest(Selection& s, std::vector<CandidateFit>& refitted, const std::vector<char>& searched,
                     RoundTally& round) {
  std::vector<int> order;
  for (int k = 0; k < static_cast<int>(refitted.size()); ++k)
    if (!searched[k]) order.push_back(k);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const bool ea = s.earlier_optima.count(refitted[a].added) > 0, eb = s.earlier_optima.count(refitted[b].added) > 0;
    if (ea != eb) return ea;
    return evidence_rmse(refitted[a]) < evidence_rmse(refitted[b]);
  });
  for (int k : order) {
    if (round.searches >= s.options.max_basin_searches) break;
    round.searches += search_for_a_better_basin(s, refitted[k]);
    note_in_round(s, refitted[k], round);
  }
}

// Moves the refitted candidates into `fits`, the best significant one
// (ranks_before) at the front.
void add_best_first(std::vector<CandidateFit>& refitted, std::vector<CandidateFit>& fits) {
  auto first = std::min_element(refitted.begin(), refitted.end(), ranks_before);
  const bool lead = first != refitted.end() && first->significant;
  if (lead) std::rotate(refitted.begin(), first, first + 1);
  fits.insert(lead ? fits.begin() : fits.end(), std::make_move_iterator(refitted.begin()),
              std::make_move_iterator(refitted.end()));
}

}  // namespace

// Two passes: every candidate refitted locally (the round's leader searched
// at once), then the searches of the rest, at most max_basin_searches in the
// round, so that whether a candidate is searched does not hang on the order
// of the refits.
void refit_candidates(Selection& s, std::vector<CandidateFit>& to_refit, std::vector<CandidateFit>& fits) {
  s.round_explained = false;
  s.round_best_excess_mm2 = std::numeric_limits<double>::infinity();
  RoundTally round;
  std::vector<char> searched;
  std::vector<CandidateFit> refitted = refit_each_locally(s, to_refit, fits, round, searched);
  search_the_rest(s, refitted, searched, round);
  for (const CandidateFit& c : refitted) note_if_immaterial(s, c);
  add_best_first(refitted, fits);
}

bool refit_from_rebased_current(Selection& s, CandidateFit& c) {
  const auto parameters = fit_parameters(c.effects);
  ModelParams start = with_effects(s.current.params, c.effects);
  for (const FitParameter& p : parameters)
    if (!p.surface && p.effect == c.added) set_parameter_value(start, p, parameter_value(c.fit.params, p));
  try {
    LeastSquaresResult again =
        fit_least_squares(s.dataset, start, parameters, s.options.fit.least_squares,
                          least_squares_progress(s.progress, "candidate " + c.added + " from the refitted current model"));
    if (!(again.sum_sq_mm2 < c.fit.sum_sq_mm2)) return false;
    char note[200];
    std::snprintf(note, sizeof note, "refitted from the refitted current model: RMSE %.4f -> %.4f mm",
                  c.fit.rmse_mm, again.rmse_mm);
    c.fit = std::move(again);
    if (s.progress) s.progress("cross-validation", 0, 1, c.added);
    cross_validate_candidate(s.dataset, parameters, s.options.fit.least_squares.replay, c);
    c.recheck_note = note;
    return true;
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    return false;  // its first fit stands
  }
}

}  // namespace hj
