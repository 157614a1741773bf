#include "calib/redundant_effects.h"

#include <algorithm>
#include <cstdio>

#include "calib/fit_parameters.h"
#include "calib/like_with_like.h"

namespace hj {

namespace {

// The current model with `effect` off, replayed at the same optimum.
LeastSquaresResult replayed_without(const Selection& s, const std::string& effect, std::vector<std::string>& rest) {
  rest = s.chosen;
  rest.erase(std::remove(rest.begin(), rest.end(), effect), rest.end());
  LeastSquaresOptions replay_only = s.options.fit.least_squares;
  replay_only.max_iterations = 0;
  return fit_least_squares(s.dataset, without_effect(s.current.params, effect), fit_parameters(rest), replay_only);
}

}  // namespace

void drop_redundant_effects(Selection& s) {
  for (size_t k = 0; s.chosen.size() > 1 && k < s.chosen.size();) {
    const std::string effect = s.chosen[k];
    if (s.progress) s.progress("redundant " + effect, 0, 1, "");
    std::vector<std::string> rest;
    LeastSquaresResult without;
    bool replays = true;
    try {
      without = replayed_without(s, effect, rest);
    } catch (const SettleInterrupted&) {
      throw;
    } catch (const std::exception&) {
      replays = false;  // the model without it has no equilibrium: it is needed
    }
    const double delta_bic = replays ? bic(without) - bic(s.current) : 0.0;
    const bool needed = !replays || delta_bic > 0.0;
    if (s.progress) s.progress("redundant " + effect, 1, 1, needed ? "kept" : "dropped");
    if (needed) {
      ++k;
      continue;
    }
    char note[400];
    std::snprintf(note, sizeof note,
                  "%s dropped: with the effects chosen after it, the model without it is no worse by BIC (RMSE "
                  "%.4f -> %.4f mm, delta BIC %.1f for %d fewer parameters)",
                  effect.c_str(), s.current.rmse_mm, without.rmse_mm, delta_bic,
                  s.current.free_parameters - without.free_parameters);
    s.out.notes.push_back(note);
    s.chosen = std::move(rest);
    s.current = std::move(without);
  }
}

}  // namespace hj
