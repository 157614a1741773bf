#include "calib/residuals.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

#include "calib/parallel_for.h"

namespace hj {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One sample's least-squares residual; a sample the prediction does not
// cover is predicted at the rig's clamp level, 0 mm (see residuals.h).
double sample_residual(double predicted, double measured) {
  return std::isnan(predicted) ? -measured : predicted - measured;
}

// Thrown by a capture check to stop a replay whose sum of squares has
// passed its caller's bound: a replay cut short, not a failed one.
struct PastBound {};

std::vector<PredictedCapture> predict(const MeasuredSession& session, const ModelParams& params,
                                      const ReplayOptions& options, const ReplayTrace* warm_start = nullptr,
                                      ReplayTrace* trace = nullptr, const CaptureSink& on_capture = {}) {
  if (!options.tally)
    return replay_session(session.session, options.segments, params.surface, simulator_options(params, options), {},
                          warm_start, trace, on_capture);
  const double cpu_start = thread_cpu_seconds();
  const bool warm = warm_start != nullptr;
  try {
    auto out = replay_session(session.session, options.segments, params.surface, simulator_options(params, options),
                              {}, warm_start, trace, on_capture);
    options.tally->add(session.session.name, thread_cpu_seconds() - cpu_start, true, warm);
    return out;
  } catch (const PastBound&) {
    options.tally->add(session.session.name, thread_cpu_seconds() - cpu_start, true, warm);
    throw;
  } catch (...) {
    options.tally->add(session.session.name, thread_cpu_seconds() - cpu_start, false, warm);
    throw;
  }
}

// Adds one capture's squared residuals (as capture_residuals makes them) to
// `running`, shared by a dataset's sessions, and stops the replay with
// PastBound once the total passes `bound` (by a relative 1e-9: the running
// sum adds in another order than the final one, and a sum at the bound
// must not be cut).
CaptureSink bound_check(const MeasuredSession& session, std::atomic<double>& running, double bound) {
  const double limit = bound + 1e-9 * std::abs(bound);
  return [&session, &running, limit, next = size_t{0}](const PredictedCapture& predicted) mutable {
    const Eigen::MatrixXd& measured = session.captures.at(next++).heights_mm;
    double sum = 0.0;
    for (int iy = 0; iy < measured.rows(); ++iy)
      for (int ix = 0; ix < measured.cols(); ++ix) {
        if (std::isnan(measured(iy, ix))) continue;
        const double r = sample_residual(predicted.heights_mm(iy, ix), measured(iy, ix));
        sum += r * r;
      }
    if (running.fetch_add(sum) + sum > limit) throw PastBound{};
  };
}

}  // namespace

double CaptureError::rmse_mm() const { return samples ? std::sqrt(sum_sq_mm2 / samples) : kNaN; }
double CaptureError::mae_mm() const { return samples ? sum_abs_mm / samples : kNaN; }
double CaptureError::share_within_accuracy() const {
  return samples ? static_cast<double>(within_accuracy) / samples : kNaN;
}

CaptureError compare_capture(const Eigen::MatrixXd& predicted_mm, const Eigen::MatrixXd& measured_mm,
                             double accuracy_mm) {
  if (predicted_mm.rows() != measured_mm.rows() || predicted_mm.cols() != measured_mm.cols())
    throw std::invalid_argument("compare_capture: predicted and measured frames differ in shape");
  CaptureError out;
  out.residual_mm = Eigen::MatrixXd::Constant(measured_mm.rows(), measured_mm.cols(), kNaN);
  double sum = 0.0;
  for (int iy = 0; iy < measured_mm.rows(); ++iy)
    for (int ix = 0; ix < measured_mm.cols(); ++ix) {
      const double measured = measured_mm(iy, ix), predicted = predicted_mm(iy, ix);
      if (std::isnan(measured)) continue;
      if (std::isnan(predicted)) {
        ++out.uncovered;
        continue;
      }
      const double r = predicted - measured;
      out.residual_mm(iy, ix) = r;
      ++out.samples;
      sum += r;
      out.sum_sq_mm2 += r * r;
      out.sum_abs_mm += std::abs(r);
      out.max_mm = std::max(out.max_mm, std::abs(r));
      if (std::abs(r) <= accuracy_mm) ++out.within_accuracy;
    }
  out.mean_mm = out.samples ? sum / out.samples : kNaN;
  return out;
}

bool cell_of_sample(const Session& session, int ix, int iy, int& r, int& c) {
  const double s = session.device.cell_size_mm;
  const double x = session.grid.x_mm(ix), y = session.grid.y_mm(iy);
  if (x < 0.0 || y < 0.0 || x > session.device.cols * s || y > session.device.rows * s) return false;
  c = std::min(static_cast<int>(std::floor(x / s)), session.device.cols - 1);
  r = std::min(static_cast<int>(std::floor(y / s)), session.device.rows - 1);
  return true;
}

double Evaluation::rmse_mm() const { return samples ? std::sqrt(sum_sq_mm2 / samples) : kNaN; }
double Evaluation::mae_mm() const { return samples ? sum_abs_mm / samples : kNaN; }
Eigen::MatrixXd Evaluation::cell_rmse_mm() const {
  Eigen::MatrixXd out(cell_samples.rows(), cell_samples.cols());
  for (int r = 0; r < out.rows(); ++r)
    for (int c = 0; c < out.cols(); ++c)
      out(r, c) = cell_samples(r, c) > 0 ? std::sqrt(cell_sum_sq_mm2(r, c) / cell_samples(r, c)) : kNaN;
  return out;
}

ReplayOptions fitting_replay(ReplayOptions options) {
  options.fallback_max_steps = std::min(options.fallback_max_steps, 20'000L);
  return options;
}

bool is_interrupted(const ReplayOptions& options) { return options.interrupted && options.interrupted(); }

void throw_if_interrupted(const ReplayOptions& options) {
  if (is_interrupted(options)) throw SettleInterrupted();
}

SimulatorOptions simulator_options(const ModelParams& params, const ReplayOptions& options) {
  SimulatorOptions out;
  out.static_options = options.solver;
  out.fallback_max_steps = options.fallbacks ? options.fallback_max_steps : 0;
  out.flow_fallback = options.fallbacks;
  out.interrupted = options.interrupted;
  params.apply_to(out);
  return out;
}

Evaluation evaluate_dataset(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                            const EvaluationProgress& progress, const std::vector<ReplayTrace>* warm_start,
                            std::vector<ReplayTrace>* traces) {
  const int n = static_cast<int>(dataset.sessions.size());
  if (traces) traces->assign(n, ReplayTrace());
  Evaluation out;
  out.sessions.resize(n);
  std::mutex mutex;
  int done = 0;
  parallel_for(
      n,
      [&](int i) {
        const MeasuredSession& measured = dataset.sessions[i];
        SessionEvaluation& result = out.sessions[i];
        result.name = measured.session.name;
        result.predicted =
            predict(measured, params, options, session_trace(warm_start, i), traces ? &(*traces)[i] : nullptr);
        for (size_t k = 0; k < measured.captures.size(); ++k)
          result.captures.push_back(compare_capture(result.predicted[k].heights_mm, measured.captures[k].heights_mm,
                                                    measured.session.sensor_accuracy_mm));
        std::lock_guard lock(mutex);
        if (progress) progress(++done, n, result.name);
      },
      options.threads);
  const SessionDevice& device = dataset.device();
  out.cell_sum_sq_mm2 = Eigen::MatrixXd::Zero(device.rows, device.cols);
  out.cell_samples = Eigen::MatrixXd::Zero(device.rows, device.cols);
  for (int i = 0; i < n; ++i) {
    const Session& session = dataset.sessions[i].session;
    for (const CaptureError& e : out.sessions[i].captures) {
      out.samples += e.samples;
      out.sum_sq_mm2 += e.sum_sq_mm2;
      out.sum_abs_mm += e.sum_abs_mm;
      for (int iy = 0; iy < e.residual_mm.rows(); ++iy)
        for (int ix = 0; ix < e.residual_mm.cols(); ++ix) {
          const double res = e.residual_mm(iy, ix);
          int r = 0, c = 0;
          if (std::isnan(res) || !cell_of_sample(session, ix, iy, r, c)) continue;
          out.cell_sum_sq_mm2(r, c) += res * res;
          out.cell_samples(r, c) += 1;
        }
    }
  }
  return out;
}

int residual_count(const MeasuredSession& session) {
  int n = 0;
  for (const auto& c : session.captures) n += static_cast<int>((c.heights_mm.array() == c.heights_mm.array()).count());
  return n;
}

Eigen::VectorXd session_residuals(const MeasuredSession& session, const ModelParams& params,
                                  const ReplayOptions& options, const ReplayTrace* warm_start, ReplayTrace* trace) {
  return capture_residuals(session, predict(session, params, options, warm_start, trace));
}

Eigen::VectorXd capture_residuals(const MeasuredSession& session, const std::vector<PredictedCapture>& predicted) {
  if (predicted.size() != session.captures.size())
    throw std::invalid_argument("capture_residuals: " + std::to_string(predicted.size()) + " predicted captures for " +
                                session.session.name + "'s " + std::to_string(session.captures.size()));
  Eigen::VectorXd out(residual_count(session));
  int k = 0;
  for (size_t c = 0; c < session.captures.size(); ++c) {
    const Eigen::MatrixXd& measured = session.captures[c].heights_mm;
    for (int iy = 0; iy < measured.rows(); ++iy)
      for (int ix = 0; ix < measured.cols(); ++ix) {
        if (std::isnan(measured(iy, ix))) continue;
        out[k++] = sample_residual(predicted[c].heights_mm(iy, ix), measured(iy, ix));
      }
  }
  return out;
}

double dataset_sum_of_squares(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                              int session_threads, double bound, const std::vector<ReplayTrace>* warm_start,
                              std::vector<ReplayTrace>* traces) {
  ReplayOptions serial = options;
  serial.threads = 1;
  const int n = static_cast<int>(dataset.sessions.size());
  std::vector<double> sums(n, 0.0);
  std::atomic<bool> failed{false}, past_bound{false};
  std::atomic<double> running{0.0};
  const bool bounded = bound < std::numeric_limits<double>::infinity();
  if (traces) traces->assign(n, ReplayTrace());
  parallel_for(
      n,
      [&](int s) {
        if (failed || past_bound) return;
        const MeasuredSession& session = dataset.sessions[s];
        try {
          const CaptureSink check = bounded ? bound_check(session, running, bound) : CaptureSink{};
          const auto predicted =
              predict(session, params, serial, session_trace(warm_start, s), traces ? &(*traces)[s] : nullptr, check);
          sums[s] = capture_residuals(session, predicted).squaredNorm();
        } catch (const PastBound&) {
          past_bound = true;
        } catch (const SettleInterrupted&) {
          throw;  // the caller stopped the work: not a failed replay
        } catch (const std::exception&) {
          failed = true;
        }
      },
      std::max(1, session_threads));
  if (failed) return std::numeric_limits<double>::infinity();
  if (past_bound) return running.load();  // above the bound: the check that stopped it saw so
  double sum = 0.0;
  for (double s : sums) sum += s;  // in session order, whatever the threads
  return sum;
}

}  // namespace hj
