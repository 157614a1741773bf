// The machine-readable documents of compare, fit and diagnose (issue 5):
// summary.json, the extra keys of a fit's params.json, diagnosis.json. Built
// here from the library's results, so the command line and the server write
// the same documents; each caller adds its own timing keys ("seconds",
// "cpu_seconds", "timing") and, for compare, the heat maps' file names.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/dataset.h"
#include "calib/diagnosis.h"
#include "calib/fit_model.h"
#include "calib/least_squares.h"
#include "calib/residuals.h"

namespace hj {

// {"spring_k": {"value", "std_error", "ci95": [lo, hi], "unit", "active", "at_bound", "loose",
//  "interval_method"}, ...}; where interval_method is not "linearised", also
// "ci95_linearised": [lo, hi] (value +- 1.96 std_error) and, if an end of
// the profile reached the parameter's bound, "ci95_open": [low, high].
nlohmann::json uncertainties_json(const LeastSquaresResult& fit);

// Sentences about the parameters that the data constrain only loosely, and
// which one they constrain least (with the relative widths of the others).
std::vector<std::string> loose_notes(const LeastSquaresResult& fit);
// A fit's notes: where the probe restarted it (FitReport::probe_notes),
// then loose_notes of its joint fit.
std::vector<std::string> fit_notes(const FitReport& report);

// summary.json of compare: {"rmse_mm", "mae_mm", "samples", "noise_floor_mm", "params",
// "sessions": [{"name", "captures": [{"frame", "label", "pressure_kpa", "jammed_cells",
// "pinned_nodes", "rmse_mm", "mae_mm", "max_mm", "mean_mm", "within_accuracy", "samples",
// "uncovered"}]}], "cells": [{"cell": [r, c], "rmse_mm", "samples"}]}.
nlohmann::json compare_summary_json(const Dataset& dataset, const ModelParams& params, const Evaluation& evaluation);

// params.json's "heldout" of a fit: {"sessions": names} and, when `held`
// has sessions, their "rmse_mm" and "mae_mm" replayed at `params`
// (progress: "held-out sessions"). Shared by `hapticjam fit` and the Fit RPC.
nlohmann::json heldout_json(const Dataset& held, const std::vector<std::string>& names, const ModelParams& params,
                            const ReplayOptions& replay,
                            const std::function<void(int, int, const std::string&)>& progress = {});

// A fit's params.json keys beside the model (model_params_json's `extra`):
// rmse_mm, r2, samples, noise_floor_mm, uncertainties, notes, heldout
// (`heldout` as given: {"sessions"[, "rmse_mm", "mae_mm"]}), levelling,
// algorithm1, least_squares, and "dataset": `dataset_name`.
nlohmann::json fit_extra_json(const Dataset& all, const FitReport& report, const nlohmann::json& heldout,
                              const std::string& dataset_name);

// diagnosis.json: {"baseline": {"rmse_mm", "heldout_rmse_mm", "r2", "params", "uncertainties"},
// "ranking": [{"effect", "effects", "rmse_mm", "heldout_rmse_mm", "delta_bic", "significant",
// "screened_out", "params", "uncertainties"[, "screening", "predicted"]}], "later_rounds",
// "verdict", "worst_cells", "findings", "skipped", "ladder", "noise_floor_mm", "final_params"}.
nlohmann::json diagnosis_json(const Diagnosis& diagnosis);

}  // namespace hj
