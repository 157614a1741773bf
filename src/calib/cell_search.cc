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

// Halfway from the default to each bound: geometrically where both are
// positive (a stiffness factor), arithmetically otherwise.
std::vector<double> probes(const ParameterSpec& spec) {
  std::vector<double> out;
  for (double bound : {spec.lower, spec.upper}) {
    if (bound == spec.default_value) continue;
    out.push_back(spec.default_value > 0.0 && bound > 0.0 ? std::sqrt(spec.default_value * bound)
                                                          : 0.5 * (spec.default_value + bound));
  }
  return out;
}

struct Point {
  int row, col;
  double value;  // the probe of the fitted parameter
  ModelParams params;
  double sum_sq = std::numeric_limits<double>::infinity();
};

// One cell's score: the lowest projected sum of squares its probes predict
// and the parameter value there.
struct CellScore {
  int row, col;
  double predicted = std::numeric_limits<double>::infinity();
  double value = 0.0;
};

// The minimum over [lower, upper] of the parabola in u = log(value) through
// the neutral value (sum of squares s0) and two probes symmetric about it in
// u; where the parabola opens downwards, the better probe. A probe is far
// from most defects' factor (0.45 against a true 0.6), so comparing cells
// by their probes alone favours whichever cell the probe happens to suit.
std::pair<double, double> parabola_minimum(double s0, const Point& low, const Point& high, const ParameterSpec& spec) {
  const double a = std::log(high.value / spec.default_value);
  const double b = (high.sum_sq - low.sum_sq) / (2.0 * a);
  const double c = (low.sum_sq + high.sum_sq - 2.0 * s0) / (2.0 * a * a);
  const double u_low = std::log(spec.lower / spec.default_value), u_high = std::log(spec.upper / spec.default_value);
  double u = low.sum_sq < high.sum_sq ? -a : a;
  if (c > 0.0) u = std::clamp(-b / (2.0 * c), u_low, u_high);
  return {s0 + b * u + c * u * u, spec.default_value * std::exp(u)};
}

// Cells best first by the sum of squares their probes predict with the
// current parameters re-solved. An effect with one fitted parameter and
// its two probes: the parabola's minimum (parabola_minimum); otherwise the
// better probe.
std::vector<CellScore> rank_cells(const std::vector<Point>& points, const std::vector<FitParameter>& parameters,
                                  const std::string& effect, const LeastSquaresResult& current,
                                  const Eigen::MatrixXd& basis) {
  const FitParameter* fitted = nullptr;
  int count = 0;
  for (const auto& p : parameters)
    if (!p.surface && p.effect == effect) fitted = &p, ++count;
  // The neutral value's projected sum of squares: the current residual off its own Jacobian.
  double s0 = current.sum_sq_mm2;
  if (basis.rows() == current.residuals.size()) s0 -= (basis.transpose() * current.residuals).squaredNorm();
  std::map<std::pair<int, int>, std::vector<const Point*>> by_cell;
  for (const Point& p : points) by_cell[{p.row, p.col}].push_back(&p);
  std::vector<CellScore> out;
  for (const auto& [cell, probes] : by_cell) {
    CellScore score{cell.first, cell.second};
    for (const Point* p : probes)
      if (p->sum_sq < score.predicted) score.predicted = p->sum_sq, score.value = p->value;
    const bool symmetric_pair = count == 1 && probes.size() == 2 && fitted->spec.default_value > 0.0 &&
                                std::isfinite(probes[0]->sum_sq) && std::isfinite(probes[1]->sum_sq);
    if (symmetric_pair) {
      const auto [low, high] = std::minmax(probes[0], probes[1], [](const Point* a, const Point* b) {
        return a->value < b->value;
      });
      const auto [predicted, value] = parabola_minimum(s0, *low, *high, fitted->spec);
      if (predicted < score.predicted) score.predicted = predicted, score.value = value;
    }
    out.push_back(score);
  }
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
                        const std::string& effect, const LeastSquaresResult& current, const LeastSquaresOptions& fit) {
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
          points.push_back({r, c, value, std::move(m)});
        }
      }
  // A probe is only a start: one only the fallbacks could settle is skipped.
  ReplayOptions point_replay = replay;
  point_replay.fallbacks = false;
  point_replay.threads = 1;
  parallel_for(
      static_cast<int>(points.size()),
      [&](int k) {
        try {
          const Eigen::VectorXd r = dataset_residuals(dataset, points[k].params, point_replay);
          points[k].sum_sq = r.squaredNorm();
          if (basis.rows() == r.size()) points[k].sum_sq -= (basis.transpose() * r).squaredNorm();
        } catch (const SettleInterrupted&) {
          throw;
        } catch (const std::exception&) {
          // No equilibrium at this probe: it stays infinite.
        }
      },
      replay.threads);
  CellSearch out;
  out.replays = static_cast<int>(points.size());
  const std::vector<CellScore> ranked = rank_cells(points, parameters, effect, current, basis);
  if (ranked.empty() || !std::isfinite(ranked.front().predicted))
    throw std::runtime_error("the model fails to replay the dataset with " + effect + " in every cell");
  // The best few cells by prediction, each fitted jointly for a few
  // iterations from its predicted value: the linearised scores rank cells
  // well but not always the first one right.
  LeastSquaresOptions short_fit = fit;
  short_fit.max_iterations = 2;
  double best_cost = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < ranked.size() && k < kCellsRefined; ++k) {
    const CellScore& cell = ranked[k];
    if (!std::isfinite(cell.predicted)) break;
    ModelParams m = start;
    m.effect_parameters[effect]["row"] = cell.row;
    m.effect_parameters[effect]["col"] = cell.col;
    for (const auto& p : parameters)
      if (!p.surface && p.effect == effect) set_parameter_value(m, p, cell.value);
    try {
      LeastSquaresResult r = fit_least_squares(dataset, m, parameters, short_fit);
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
      // This cell's fit does not replay: the next one.
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
  std::snprintf(text, sizeof text, "%s at cell [%d, %d]%s (best of %zu cells fitted; sum of squares %+.1f %%)",
                effect.c_str(), out.row, out.col, values.c_str(), std::min(ranked.size(), kCellsRefined),
                -100.0 * (1.0 - best_cost / current.sum_sq_mm2));
  out.note = text;
  return out;
}

}  // namespace hj
