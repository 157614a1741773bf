#include "calib/range_start.h"

namespace hj {

void start_from_best_of_range(const Dataset& dataset, const ModelParams& current, const DiagnoseOptions& options,
                              const DiagnoseProgress& progress, CandidateFit& c) {
  if (options.multi_start.starts < 1 || !wants_multi_start(c.added)) return;
  // The short fits are a cheap look over the range; under a cap no longer
  // than they are, each would be a whole refit.
  if (options.fit.least_squares.max_iterations <= options.multi_start.iterations) return;
  const auto parameters = fit_parameters(c.effects);
  const ModelParams scanned = c.scanned_start ? *c.scanned_start : with_effects(current, c.effects);
  if (progress) progress("multi-start " + c.added, 0, 1, "");
  MultiStart range = multi_start(dataset, scanned, parameters, c.added, options.fit.least_squares,
                                 options.multi_start);
  // The scan's start on the same footing: its own short fit.
  const LeastSquaresOptions short_fit = start_fit_options(options.fit.least_squares, options.multi_start.iterations);
  c.multi_start_parameter = range.parameter;
  c.starts_tried = range.tried;
  try {
    const LeastSquaresResult from_scan = fit_least_squares(dataset, scanned, parameters, short_fit);
    for (const auto& p : parameters)
      if (!p.surface && p.effect == c.added)
        c.starts_tried.push_back(
            {p.qualified_name(), parameter_value(scanned, p), from_scan.rmse_mm, parameter_value(from_scan.params, p)});
    if (from_scan.sum_sq_mm2 <= range.best_sum_sq_mm2) {
      c.scanned_start = from_scan.params;
      range.found = false;
    }
  } catch (const SettleInterrupted&) {
    throw;
  } catch (const std::exception&) {
    // The scan's start does not replay: the range's best stands.
  }
  if (range.found) c.scanned_start = range.best;
  if (progress) progress("multi-start " + c.added, 1, 1, "");
}

std::optional<ModelParams> better_start_than_local(const Dataset& dataset, const LeastSquaresResult& local,
                                                   const DiagnoseOptions& options, const DiagnoseProgress& progress,
                                                   CandidateFit& c) {
  if (options.multi_start.starts < 1 || !wants_multi_start(c.added)) return std::nullopt;
  if (progress) progress("multi-start " + c.added, 0, 1, "");
  const MultiStart range = multi_start(dataset, local.params, fit_parameters(c.effects), c.added,
                                       options.fit.least_squares, options.multi_start);
  c.multi_start_parameter = range.parameter;
  c.starts_tried = range.tried;
  if (progress) progress("multi-start " + c.added, 1, 1, "");
  if (range.found && range.best_sum_sq_mm2 < local.sum_sq_mm2) return range.best;
  return std::nullopt;
}

}  // namespace hj
