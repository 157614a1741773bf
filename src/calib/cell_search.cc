#include "calib/cell_search.h"

#include <Eigen/QR>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "calib/parallel_for.h"

namespace hj {

namespace {

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
  ModelParams params;
  double sum_sq = std::numeric_limits<double>::infinity();
};

}  // namespace

bool is_cell_effect(const std::string& effect) {
  int found = 0;
  for (const auto& spec : EffectRegistry::instance().get(effect).parameters)
    if (!is_fitted(spec) && (spec.name == "row" || spec.name == "col")) ++found;
  return found == 2;
}

CellSearch search_cells(const Dataset& dataset, const ModelParams& start, const std::vector<FitParameter>& parameters,
                        const std::string& effect, const LeastSquaresResult& current, const ReplayOptions& replay) {
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
          points.push_back({r, c, std::move(m)});
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
  const Point* best = nullptr;
  for (const Point& p : points)
    if (std::isfinite(p.sum_sq) && (!best || p.sum_sq < best->sum_sq)) best = &p;
  if (!best) throw std::runtime_error("the model fails to replay the dataset with " + effect + " in every cell");
  out.best = best->params;
  out.row = best->row;
  out.col = best->col;
  out.best_sum_sq_mm2 = best->sum_sq;
  std::string values;
  char text[200];
  for (const auto& p : parameters)
    if (!p.surface && p.effect == effect) {
      std::snprintf(text, sizeof text, ", %s %.3g", p.spec.name.c_str(), parameter_value(out.best, p));
      values += text;
    }
  std::snprintf(text, sizeof text, "%s at cell [%d, %d]%s (sum of squares, the current parameters re-solved: %+.1f %%)", effect.c_str(), out.row, out.col,
                values.c_str(), -100.0 * (1.0 - best->sum_sq / current.sum_sq_mm2));
  out.note = text;
  return out;
}

}  // namespace hj
