#include "calib/cell_search.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>

#include "calib/parallel_for.h"

namespace hj {

namespace {

// How many of the best-predicted cells get a short joint fit.
constexpr size_t kCellsRefined = 3;

// How many times a probe that does not replay is retried at half its step
// (a replay has no noise, so a twentieth of the step still gives its direction).
constexpr int kProbeHalvings = 4;

// Halfway from the default to `bound`: geometrically where both are
// positive (a stiffness factor), arithmetically otherwise.
double halfway(const ParameterSpec& spec, double bound) {
  return spec.default_value > 0.0 && bound > 0.0 ? std::sqrt(spec.default_value * bound)
                                                 : 0.5 * (spec.default_value + bound);
}

// Halfway from the default to each bound.
std::vector<double> probes(const ParameterSpec& spec) {
  std::vector<double> out;
  for (double bound : {spec.lower, spec.upper})
    if (bound != spec.default_value) out.push_back(halfway(spec, bound));
  return out;
}

struct Point {
  int row, col;
  const FitParameter* parameter;  // the fitted parameter probed
  double value;                   // its probe
  ModelParams params;
  // The sum of squares the linear model predicts along this probe's
  // direction, the current parameters re-solved, and the value there.
  double predicted = std::numeric_limits<double>::infinity();
  double predicted_value = 0.0;
  int replays = 0;
};

// One cell's score: the lowest sum of squares its probes predict and the
// parameter value there.
struct CellScore {
  int row, col;
  double predicted = std::numeric_limits<double>::infinity();
  double value = 0.0;
  const Point* probe = nullptr;  // the probe that predicts it
};

// The score along one probe: with d = r(probe) - r0 and both taken off the
// current Jacobian's columns (the current parameters re-solved), the least
// squares step t d (t >= 0, in units of the probe's own step, within the
// bounds) predicts |r0 + t d|^2. Only the probe's direction matters, not
// its size, so a defect between the probes (0.6 against a probe of 0.45)
// is judged at its own size: comparing the probes' own sums of squares
// favours whichever cell the probe's size happens to suit.
void predict_along_probe(const Eigen::VectorXd& r0_off, const Eigen::VectorXd& r, const Eigen::VectorXd& r0,
                         const Eigen::MatrixXd& basis, const ParameterSpec& spec, Point& point) {
  Eigen::VectorXd d = r - r0;
  if (basis.rows() == d.size()) d -= basis * (basis.transpose() * d);
  const double dot = d.dot(r0_off), nn = d.squaredNorm();
  if (!(nn > 0.0)) return;
  const bool geometric = spec.default_value > 0.0 && point.value > 0.0;
  const double step = geometric ? std::log(point.value / spec.default_value) : point.value - spec.default_value;
  const double to_bound = geometric ? std::log((step > 0 ? spec.upper : spec.lower) / spec.default_value)
                                    : (step > 0 ? spec.upper : spec.lower) - spec.default_value;
  const double t = std::clamp(-dot / nn, 0.0, to_bound / step);
  point.predicted = r0_off.squaredNorm() + 2.0 * t * dot + t * t * nn;
  point.predicted_value = geometric ? spec.default_value * std::exp(t * step) : spec.default_value + t * step;
}

// Replays the dataset at `point` and predicts along it. Only the probe's
// direction counts, so one with no equilibrium (a soft cell folding under
// a baseline that absorbed the defect) is retried at half its step.
void replay_probe(const Dataset& dataset, const ReplayOptions& replay, const Eigen::VectorXd& r0_off,
                  const Eigen::VectorXd& r0, const Eigen::MatrixXd& basis, Point& point) {
  for (int halvings = 0;; ++halvings) {
    try {
      ++point.replays;
      const Eigen::VectorXd r = dataset_residuals(dataset, point.params, replay);
      if (r.size() == r0.size()) predict_along_probe(r0_off, r, r0, basis, point.parameter->spec, point);
      return;
    } catch (const SettleInterrupted&) {
      throw;
    } catch (const std::exception&) {
      if (halvings == kProbeHalvings) return;  // no equilibrium near this probe: it predicts nothing
    }
    point.value = halfway(point.parameter->spec, point.value);
    set_parameter_value(point.params, *point.parameter, point.value);
  }
}

// `start` with `effect` in cell (row, col) and its fitted parameters at `value`.
ModelParams in_cell(const ModelParams& start, const std::vector<FitParameter>& parameters, const std::string& effect,
                    int row, int col, double value) {
  ModelParams m = start;
  m.effect_parameters[effect]["row"] = row;
  m.effect_parameters[effect]["col"] = col;
  for (const auto& p : parameters)
    if (!p.surface && p.effect == effect) set_parameter_value(m, p, value);
  return m;
}

// Cells best first by the lowest sum of squares any of their probes predicts.
std::vector<CellScore> rank_cells(const std::vector<Point>& points) {
  std::map<std::pair<int, int>, CellScore> by_cell;
  for (const Point& p : points) {
    CellScore& score = by_cell.try_emplace({p.row, p.col}, CellScore{p.row, p.col, std::numeric_limits<double>::infinity(), 0.0, nullptr}).first->second;
    if (p.predicted < score.predicted) score.predicted = p.predicted, score.value = p.predicted_value, score.probe = &p;
  }
  std::vector<CellScore> out;
  for (const auto& [cell, score] : by_cell) out.push_back(score);
  std::stable_sort(out.begin(), out.end(), [](const CellScore& a, const CellScore& b) { return a.predicted < b.predicted; });
  return out;
}

}  // namespace

bool is_cell_effect(const std::string& effect) {
  int found = 0;
  for (const auto& spec : EffectRegistry::instance().get(effect).parameters)
    if (!is_fitted(spec) && (spec.name == "row" || spec.name == "col")) ++found;
  return found == 2;
}

CellSearch search_cells(const Dataset& dataset, const ModelParams& start, const std::vector<FitParameter>& parameters,
                        const std::string& effect, const LeastSquaresResult& current, const LeastSquaresOptions& fit,
                        double refine_below) {
  const ReplayOptions& replay = fit.replay;
  // An orthonormal basis of the current Jacobian's columns (none if the fit has none).
  Eigen::MatrixXd basis;
  if (current.jacobian.cols() > 0 && current.jacobian.rows() == current.residuals.size()) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(current.jacobian);
    basis = qr.householderQ() * Eigen::MatrixXd::Identity(current.jacobian.rows(), current.jacobian.cols());
  }
  const SessionDevice& device = dataset.sessions.front().session.device;
  std::vector<Point> points;
  for (int r = 0; r < device.rows; ++r)
    for (int c = 0; c < device.cols; ++c)
      for (const auto& p : parameters) {
        if (p.surface || p.effect != effect) continue;
        for (double value : probes(p.spec)) {
          ModelParams m = start;
          m.effect_parameters[effect]["row"] = r;
          m.effect_parameters[effect]["col"] = c;
          set_parameter_value(m, p, value);
          points.push_back({r, c, &p, value, std::move(m)});
        }
      }
  // A probe is only a start: one only the fallbacks could settle is skipped.
  ReplayOptions point_replay = replay;
  point_replay.fallbacks = false;
  point_replay.threads = 1;
  const Eigen::VectorXd& r0 = current.residuals;
  Eigen::VectorXd r0_off = r0;
  if (basis.rows() == r0.size()) r0_off -= basis * (basis.transpose() * r0);
  parallel_for(
      static_cast<int>(points.size()),
      [&](int k) { replay_probe(dataset, point_replay, r0_off, r0, basis, points[k]); },
      replay.threads);
  CellSearch out;
  for (const Point& p : points) out.replays += p.replays;
  const std::vector<CellScore> ranked = rank_cells(points);
  if (ranked.empty() || !std::isfinite(ranked.front().predicted))
    throw std::runtime_error("the model fails to replay the dataset with " + effect + " in every cell");
  // The best few cells by prediction, each fitted jointly for a few
  // iterations: the linearised scores rank cells well but not always the
  // first one right (a baseline that absorbed the defect is far from the
  // truth; at 2 iterations a 0.6 k cell still lost to a stiff one elsewhere).
  const LeastSquaresOptions short_fit = start_fit_options(fit, 4);
  double best_cost = std::numeric_limits<double>::infinity();
  const size_t refined = ranked.front().predicted < refine_below ? kCellsRefined : 0;
  if (refined == 0) {
    const CellScore& cell = ranked.front();
    out.best = in_cell(start, parameters, effect, cell.row, cell.col, cell.value);
    out.row = cell.row;
    out.col = cell.col;
    best_cost = cell.predicted;
  }
  for (size_t k = 0; k < ranked.size() && k < refined; ++k) {
    const CellScore& cell = ranked[k];
    if (!std::isfinite(cell.predicted)) break;
    // From the predicted value and from the probe on its side: where the
    // current fit is far from the truth the linear prediction falls short.
    for (double value : {cell.value, cell.probe->value}) {
      try {
        LeastSquaresResult r = fit_least_squares(
            dataset, in_cell(start, parameters, effect, cell.row, cell.col, value), parameters, short_fit);
        out.replays += r.evaluations + r.jacobians * r.free_parameters;
        if (r.sum_sq_mm2 < best_cost) {
          best_cost = r.sum_sq_mm2;
          out.best = std::move(r.params);
          out.row = cell.row;
          out.col = cell.col;
        }
      } catch (const SettleInterrupted&) {
        throw;
      } catch (const std::exception&) {
        // This start does not replay: the next one.
      }
    }
  }
  if (!std::isfinite(best_cost))
    throw std::runtime_error("the model fails to fit the dataset with " + effect + " in any of its best cells");
  out.best_sum_sq_mm2 = best_cost;
  std::string values;
  char text[200];
  for (const auto& p : parameters)
    if (!p.surface && p.effect == effect) {
      std::snprintf(text, sizeof text, ", %s %.3g", p.spec.name.c_str(), parameter_value(out.best, p));
      values += text;
    }
  if (refined > 0)
    std::snprintf(text, sizeof text, "%s at cell [%d, %d]%s (best of %zu cells fitted; sum of squares %+.1f %%)",
                  effect.c_str(), out.row, out.col, values.c_str(), std::min(ranked.size(), refined),
                  -100.0 * (1.0 - best_cost / current.sum_sq_mm2));
  else
    std::snprintf(text, sizeof text,
                  "%s at cell [%d, %d]%s (predicted, not fitted: sum of squares %+.1f %%, far above another "
                  "effect's scan)",
                  effect.c_str(), out.row, out.col, values.c_str(), -100.0 * (1.0 - best_cost / current.sum_sq_mm2));
  out.note = text;
  return out;
}

}  // namespace hj
