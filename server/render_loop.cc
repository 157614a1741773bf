#include "render_loop.h"

#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "calib/measurement_effects.h"
#include "json_log.h"
#include "metrics/correction_screen.h"
#include "metrics/height_error.h"
#include "plan/planner.h"
#include "render_calibration.h"
#include "render_frames.h"
#include "render_expectation.h"
#include "render_jobs.h"
#include "service_error.h"
#include "sim/settle_report.h"
#include "sim/simulator.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using Clock = std::chrono::steady_clock;
using grpc::StatusCode;

namespace {

// An iteration must beat the best so far by this share of its error, or the
// error has stopped falling (camera noise moves it by about this much).
constexpr double kMinImprovement = 0.02;

// Corrections of a screened plan in the model before it runs (refined_in_model).
constexpr int kModelCorrections = 2;

// A device's sag turns into a dome somewhere past the model's levelling
// pressure (PlanRequest::levelling_margin): a plan that jams there jams a
// device still in its sag. 1.5 x levelling domes on the stiffening emulator
// at p = 8 where 1.12 x does not (docs/render.md).
constexpr double kDeviceLevellingMargin = 1.5;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool learns_targets(v1::RenderCorrection c) {
  return c == v1::RENDER_CORRECTION_TARGETS || c == v1::RENDER_CORRECTION_BOTH;
}
bool fits_model(v1::RenderCorrection c) { return c == v1::RENDER_CORRECTION_MODEL || c == v1::RENDER_CORRECTION_BOTH; }

class RenderRun {
 public:
  RenderRun(const RenderSetup& setup, DeviceQueue& queue, const Caller& caller, const RenderHooks& hooks)
      : setup_(setup), queue_(queue), caller_(caller), hooks_(hooks), mesh_(setup.array.geometry),
        targets_(setup.goal_mm),
        calibration_(setup.array.geometry, model_params_of(setup.array.params, setup.array.simulator), setup.fit_threads,
                     hooks.cancelled) {}

  v1::RenderResult run() {
    check_device();
    const auto start = Clock::now();
    v1::RenderResult result;
    result.set_point_rows(mesh_.point_rows()), result.set_point_cols(mesh_.point_cols());
    add_heights(setup_.goal_mm, result.mutable_goal_heights_mm());
    std::string stop = "the iteration limit (" + std::to_string(setup_.iterations) + ")";
    for (int i = 1; i <= setup_.iterations; ++i) {
      std::optional<v1::RenderIteration> ran = iterate(i);
      if (!ran) {
        stop = screen_stop_;
        break;
      }
      v1::RenderIteration& it = *ran;
      result.add_job_ids(it.job_id());
      result.set_iterations(i);
      if (i == 1) *result.mutable_open_loop_error() = it.error();
      const double mae = it.error().mae_mm();
      const bool improved = mae < best_mae_ * (1.0 - kMinImprovement);
      if (mae < best_mae_) {
        best_mae_ = mae;
        result.set_best_iteration(i);
        *result.mutable_error() = it.error();
        best_steps_ = last_steps_;
      }
      const bool last = i == setup_.iterations;
      if (!improved && i > 1) stop = "the error stopped falling (iteration " + std::to_string(i) + ")";
      // The model is fitted once and the targets stay the goal: a next plan would repeat this one.
      const bool repeats = setup_.correction == v1::RENDER_CORRECTION_MODEL && i > 1 && improved && !last;
      if (repeats) stop = "the fitted model's plan ran (iteration " + std::to_string(i) + "); a next one would repeat it";
      const bool stopping = last || (!improved && i > 1) || repeats;
      if (stopping) it.set_correction("none: the render ends here");
      emit_iteration(std::move(it));
      if (stopping) break;
    }
    result.set_stop_reason(stop);
    if (result.best_iteration() > 0 && (result.best_iteration() != result.iterations() || !device_shows_last_run_))
      leave_at_best(result);
    if (fits_model(setup_.correction)) *result.mutable_model() = last_model_;
    result.set_seconds(seconds_since(start));
    return result;
  }

 private:
  void check_device() {
    const v1::DeviceStatus status = queue_.device_status();
    const ArrayGeometry& g = setup_.array.geometry;
    if (status.connected() && (status.rows() != g.rows || status.cols() != g.cols))
      throw ServiceError(StatusCode::FAILED_PRECONDITION,
                         "the device is a " + std::to_string(status.rows()) + " x " + std::to_string(status.cols()) +
                             " array; the render asks for " + std::to_string(g.rows) + " x " + std::to_string(g.cols));
  }

  void progress(int iteration, double within, const std::string& what) {
    v1::RenderEvent event;
    v1::RenderProgress* p = event.mutable_progress();
    p->set_iteration(iteration);
    p->set_fraction(std::clamp((iteration - 1 + within) / setup_.iterations, 0.0, 1.0));
    p->set_message(what);
    hooks_.emit(std::move(event));
  }

  void emit_iteration(v1::RenderIteration it) {
    v1::RenderEvent event;
    *event.mutable_iteration() = std::move(it);
    hooks_.emit(std::move(event));
  }

  // The fitted model (the request's until a fit), its camera left out: a planner plans surfaces.
  struct PlanningModel {
    SurfaceParameters surface;
    SimulatorOptions simulator;
  };
  PlanningModel planning_model() const {
    const ModelParams model = without_measurement_effects(calibration_.model());
    PlanningModel out{model.surface, setup_.array.simulator};
    model.apply_to(out.simulator);
    return out;
  }

  PlanResult plan(int iteration) {
    const PlanningModel model = planning_model();
    // The loop measures millimetres: a planner choosing among surfaces chooses by them.
    PlanRequest request{setup_.array.geometry, model.surface, targets_, model.simulator, {}, PlanScoring::kHeightError};
    request.params.max_pressure_pa = std::min(request.params.max_pressure_pa, pressure_limit_pa_);
    request.levelling_margin = kDeviceLevellingMargin;
    PlanCallbacks callbacks;
    callbacks.cancelled = hooks_.cancelled;
    callbacks.progress = [&](double fraction, const std::string& what) {
      progress(iteration, 0.5 * fraction, "planning: " + what);
    };
    try {
      return make_planner(setup_.planner)->plan(request, callbacks);
    } catch (const PlanCancelled&) {
      throw ServiceError(StatusCode::CANCELLED, "the render was cancelled while planning iteration " +
                                                    std::to_string(iteration));
    }
  }

  // The planning model's surface after `steps` from rest: the prediction
  // for a run the device cut short.
  DeviceState predicted_after(int iteration, const std::vector<Action>& steps) const {
    PlanningModel model = planning_model();
    model.simulator.interrupted = hooks_.cancelled;
    Simulator simulator(setup_.array.geometry, model.surface, model.simulator);
    try {
      for (const Action& a : steps) simulator.apply(a);
    } catch (const SettleInterrupted&) {
      throw ServiceError(StatusCode::CANCELLED, "the render was cancelled while predicting iteration " +
                                                    std::to_string(iteration) + "'s shortened run");
    }
    return simulator.state();
  }

  // A run as a device job (a job starts vented); waits for it to end.
  v1::Job run_on_device(int iteration, const std::vector<Action>& steps, const std::string& which) {
    const std::string name = setup_.name + " iteration " + std::to_string(iteration) + which;
    device_shows_last_run_ = true;
    return run_job(iteration, name, run_job_plan(name, steps));
  }

  // The probe the model is fitted on. The device is left on its last dome.
  v1::Job run_probe(int iteration, const std::vector<Action>& probe) {
    const std::string name = setup_.name + " probe";
    device_shows_last_run_ = false;
    return run_job(iteration, name, probe_job_plan(name, probe));
  }

  v1::Job run_job(int iteration, const std::string& name, v1::Plan plan) {
    plan.set_planner(setup_.planner);
    RenderJobHooks hooks;
    hooks.queued = [&](const v1::Job& job) {
      log_event("render_job", {{"job", job.id()}, {"iteration", iteration}});
    };
    hooks.cancelled = hooks_.cancelled;
    hooks.progress = [&](const v1::Job& job) {
      progress(iteration, 0.5 + 0.5 * job.steps_done() / std::max(1, job.steps_total()),
               "on the device: step " + std::to_string(job.steps_done()) + " of " + std::to_string(job.steps_total()) +
                   (job.position() > 0 ? " (position " + std::to_string(job.position()) + " in the queue)" : ""));
    };
    return run_device_job(queue_, caller_, name, plan, hooks);
  }

  [[noreturn]] void throw_unfinished(const v1::Job& job, const std::string& what) const {
    server::throw_unfinished(job, what, hooks_.cancelled());
  }

  // The device holds what it ran last; a render ends with it showing the
  // best run's surface, so when a later run was worse the best run's steps
  // run again. The repeat's error against the goal is reported beside the
  // best's (the camera's noise differs; the surface is the same). A device
  // that refuses the repeat leaves the render's figures as they are, and
  // the stop reason says so.
  void leave_at_best(v1::RenderResult& result) {
    const int best = result.best_iteration();
    progress(result.iterations(), 1.0, "running iteration " + std::to_string(best) + "'s steps again: the best run");
    const v1::Job job = run_on_device(best, best_steps_, " again (the best run)");
    result.set_best_again_job_id(job.id());
    log_event("render_best_again", {{"job", job.id()}, {"iteration", best}});
    if (job.state() == v1::JOB_STATE_FAILED) {
      result.set_stop_reason(result.stop_reason() + "; the device refused the best run's steps again (job " +
                             std::to_string(job.id()) + ": " + job.error() + ")");
      return;
    }
    if (job.state() != v1::JOB_STATE_DONE || job.captures_size() < 2)
      throw_unfinished(job, "running the best iteration (" + std::to_string(best) + ") again");
    const v1::CaptureFrame& capture = job.captures(job.captures_size() - 1);
    v1::CameraPlane camera;
    const Eigen::MatrixXd measured = calibrated(best, frame_heights(capture), capture.grid(), job.captures(0), &camera);
    try {
      error_to_proto(height_error(setup_.goal_mm, measured), result.mutable_best_again_error());
    } catch (const std::invalid_argument& e) {
      throw ServiceError(StatusCode::ABORTED, "running the best iteration again: " + std::string(e.what()));
    }
  }

  // The device could not complete a step its model settles (a device is
  // not the model): the iteration is run again up to the step before, so it
  // ends where the device stood and the correction works on what it made.
  // Shortens `steps` and moves `predicted` to match; the new job.
  v1::Job rerun_before_refusal(int i, const v1::Job& refused, std::vector<Action>& steps, DeviceState& predicted,
                               v1::RenderIteration& it) {
    it.set_refusal(refused.error());
    it.set_refused_job_id(refused.id());
    learn_pressure_limit(steps, size_t(actions_done(refused)));
    steps.resize(size_t(actions_done(refused)));
    log_event("render_step_refused", {{"job", refused.id()}, {"iteration", i}, {"step", actions_done(refused)}});
    progress(i, 0.5, "the device refused step " + std::to_string(steps.size()) + "; running the " +
                         std::to_string(steps.size()) + " steps before it");
    predicted = predicted_after(i, steps);
    return run_on_device(i, steps, " (first " + std::to_string(steps.size()) + " steps)");
  }

  // A pressure the device refused to settle at is past what it can do (a
  // real array as the emulator, whose settle there did not finish): later
  // plans stay at or below the pressure it stood at before it.
  void learn_pressure_limit(const std::vector<Action>& steps, size_t refused) {
    const double floor = 2.0 * kDeviceLevellingMargin * setup_.array.params.levelling_pressure_pa(mesh_);
    pressure_limit_pa_ = std::min(pressure_limit_pa_, pressure_limit_after_refusal(steps, refused, floor));
  }

  // One run: plan (screened from the second on), run on the device,
  // capture, compare, correct; nullopt when the screen ends the render.
  std::optional<v1::RenderIteration> iterate(int i) {
    v1::RenderIteration it;
    it.set_iteration(i);
    const auto planning_start = Clock::now();
    std::optional<PlanResult> planned = plan(i);
    if (targets_moved_) {
      planned = screened(i, std::move(*planned), it);
    } else if (i > 1 && learns_targets(setup_.correction)) {
      // The first plan of a refitted model: nothing to screen against yet,
      // but its prediction can correct its targets.
      RenderExpectation::Expected expected = expected_of(i, *planned);
      std::ostringstream s;
      s.precision(3);
      s << "the refitted model's plan, predicted " << expected.mae_mm << " mm";
      refined_in_model(i, *planned, expected, s);
      it.set_screening(s.str());
    }
    it.set_planning_seconds(seconds_since(planning_start));
    if (!planned) return std::nullopt;

    for (const Action& a : planned->steps) action_to_proto(a, it.mutable_plan()->add_steps());
    it.mutable_plan()->set_planner(setup_.planner);

    const auto device_start = Clock::now();
    std::vector<Action> steps = planned->steps;
    DeviceState predicted_state = planned->final_state;
    v1::Job job = run_on_device(i, steps, "");
    if (refused_part_way(job, steps.size())) job = rerun_before_refusal(i, job, steps, predicted_state, it);
    it.set_steps_run(int(steps.size()));
    last_steps_ = steps;
    it.set_device_seconds(seconds_since(device_start));
    it.set_job_id(job.id());
    if (job.state() != v1::JOB_STATE_DONE || job.captures_size() < 2)
      throw_unfinished(job, "render iteration " + std::to_string(i));
    *it.mutable_rest_capture() = job.captures(0);
    *it.mutable_capture() = job.captures(job.captures_size() - 1);

    const Eigen::MatrixXd frame = frame_heights(it.capture());
    if (fits_model(setup_.correction)) fit_model(i, steps, it);
    const Eigen::MatrixXd measured = calibrated(i, frame, it.capture().grid(), it.rest_capture(), it.mutable_camera());
    const Eigen::MatrixXd predicted = predicted_at_rest_points(mesh_, predicted_state.x, it.capture().grid());
    it.set_point_rows(mesh_.point_rows()), it.set_point_cols(mesh_.point_cols());
    add_heights(measured, it.mutable_measured_heights_mm());
    add_heights(predicted, it.mutable_predicted_heights_mm());
    add_heights(targets_, it.mutable_target_heights_mm());
    try {
      error_to_proto(height_error(setup_.goal_mm, measured), it.mutable_error());
      error_to_proto(height_error(predicted, measured), it.mutable_prediction_error());
    } catch (const std::invalid_argument& e) {
      throw ServiceError(StatusCode::ABORTED, "render iteration " + std::to_string(i) + ": " + e.what());
    }
    previous_targets_ = targets_;
    expectation_.after_run(measured, predicted, it.capture().grid());
    it.set_correction(correct(whole_plan_outcome(measured, predicted, *planned, it), it));
    return it;
  }

  // A corrected plan runs only if the device is expected to make it no
  // clearly worse than its best run (metrics/correction_screen.h); else the
  // correction is halved and replanned. nullopt: none passed, the render
  // ends at its best (screen_stop_ says why).
  std::optional<PlanResult> screened(int i, PlanResult planned, v1::RenderIteration& it) {
    const CorrectionScreenOptions options;
    std::ostringstream s;
    s.precision(3);
    for (int halvings = 0;; ++halvings) {
      RenderExpectation::Expected expected = expected_of(i, planned);
      s << (halvings ? ", then " : "expected ") << expected.mae_mm << " mm";
      if (passes_screen(expected.mae_mm, best_mae_, options)) {
        s << " against the best run's " << best_mae_ << " mm: run";
        if (halvings) s << ", the correction halved " << halvings << (halvings > 1 ? " times" : " time");
        refined_in_model(i, planned, expected, s);
        it.set_screening(s.str());
        return planned;
      }
      if (halvings == options.max_halvings) {
        s << " against the best run's " << best_mae_ << " mm, the correction halved " << halvings << " times";
        screen_stop_ = "the corrected plans were expected worse than the best run (" + s.str() + ")";
        log_event("render_screen_stop", {{"iteration", i}, {"reason", screen_stop_}});
        return std::nullopt;
      }
      progress(i, 0.0, "the corrected plan is expected worse than the best run: halving the correction");
      targets_ = halved_correction(previous_targets_, targets_);
      planned = plan(i);
    }
  }

  // A plan that passed the screen, corrected again in the model: the
  // targets moved by the goal's difference from what the device is
  // expected to make of it, and replanned, while that is expected better
  // (kModelCorrections at most). A step costs a plan, not a run on the
  // device; with a fitted model, the expectations of the first fitted
  // plans at 6 x 8 came within 0.15 mm of their runs.
  void refined_in_model(int i, PlanResult& planned, RenderExpectation::Expected& expected, std::ostringstream& s) {
    for (int k = 0; k < kModelCorrections; ++k) {
      const Eigen::MatrixXd kept = targets_;
      targets_ = learned_targets(targets_, setup_.goal_mm, expected.surface, 1.0);
      progress(i, 0.0, "correcting the plan in the model");
      PlanResult again = plan(i);
      RenderExpectation::Expected e = expected_of(i, again);
      if (!(e.mae_mm < expected.mae_mm * (1.0 - kMinImprovement))) {
        targets_ = kept;
        return;
      }
      s << "; corrected in the model: expected " << e.mae_mm << " mm";
      planned = std::move(again), expected = std::move(e);
    }
  }

  RenderExpectation::Expected expected_of(int i, const PlanResult& planned) const {
    try {
      return expectation_.of(planned);
    } catch (const std::invalid_argument& e) {
      throw ServiceError(StatusCode::ABORTED, "render iteration " + std::to_string(i) + ": screening its plan: " +
                                                  e.what());
    }
  }

  // After the first run that a next one follows: the device's probe, up to
  // the pressures that shaped the run, and the device model fitted on it;
  // the next iterations plan with it.
  void fit_model(int i, const std::vector<Action>& steps, v1::RenderIteration& it) {
    if (calibration_.fitted() || i == setup_.iterations) return;
    std::vector<Action> probe;
    try {
      probe = calibration_.probe(kDeviceLevellingMargin, steps, setup_.goal_mm.maxCoeff());
    } catch (const SettleInterrupted&) {
      throw ServiceError(StatusCode::CANCELLED, "the render was cancelled while choosing the probe's pressures");
    }
    progress(i, 0.9, "probing the device: " + std::to_string(probe.size()) + " pressures of the free membrane");
    const v1::Job job = run_probe(i, probe);
    const bool cut_short = job.state() == v1::JOB_STATE_FAILED && job.captures_size() >= 2;
    if (job.state() != v1::JOB_STATE_DONE && !cut_short) throw_unfinished(job, "the probe");
    std::vector<Eigen::MatrixXd> frames;
    for (const v1::CaptureFrame& c : job.captures()) frames.push_back(frame_heights(c));
    progress(i, 0.95, "fitting the model on the probe's " + std::to_string(frames.size()) + " captures");
    const auto start = Clock::now();
    try {
      calibration_.fit_probe(probe, session_grid(job.captures(0).grid()), frames, it.mutable_model());
    } catch (const SettleInterrupted&) {
      throw ServiceError(StatusCode::CANCELLED, "the render was cancelled while fitting the model");
    } catch (const std::exception& e) {
      throw ServiceError(StatusCode::ABORTED, "render iteration " + std::to_string(i) + ": the model fit failed: " +
                                                  e.what());
    }
    it.mutable_model()->set_probe_job_id(job.id());
    it.set_fitting_seconds(seconds_since(start));
    last_model_ = it.model();
    log_event("render_fit", {{"iteration", i}, {"probe_job", job.id()}, {"rmse_mm", it.model().rmse_mm()},
                             {"seconds", it.fitting_seconds()}});
  }

  // A capture (its heights on its grid) at the mesh points, with the
  // camera's plane taken out: the fitted sensor_tilt where the model is
  // fitted, else the plane fitted on the clamped edge in the capture at
  // rest (a shaped membrane can bulge over its edge).
  Eigen::MatrixXd calibrated(int i, const Eigen::MatrixXd& frame, const v1::CaptureGrid& grid,
                             const v1::CaptureFrame& rest, v1::CameraPlane* out) {
    const Eigen::MatrixXd seen = frame_at_rest_points(mesh_, frame, frame_grid(grid));
    if (setup_.keep_camera_plane) {
      camera_to_proto({}, "none", out);
      return seen;
    }
    if (calibration_.fitted()) {
      const CameraPlane plane = calibration_.camera();
      const bool found = plane.tilt_x_mrad != 0.0 || plane.tilt_y_mrad != 0.0 || plane.offset_mm != 0.0;
      camera_to_proto(plane, found ? "fitted sensor_tilt" : "none", out);
      return without_camera_plane(mesh_, seen, plane);
    }
    CameraPlane plane;
    try {
      plane = fit_camera_plane(mesh_, frame_at_rest_points(mesh_, frame_heights(rest), frame_grid(rest.grid())));
    } catch (const std::invalid_argument& e) {
      throw ServiceError(StatusCode::ABORTED, "render iteration " + std::to_string(i) + ": the capture at rest: " +
                                                  e.what());
    }
    camera_to_proto(plane, "clamped edge at rest", out);
    return without_camera_plane(mesh_, seen, plane);
  }

  // What the whole plan would have made on the device, for the targets
  // correction: the capture itself, or after a refusal the model's whole-plan
  // surface moved by the device's departure from the model on the steps it
  // did run (the unrun steps are not the device's answer to the targets).
  Eigen::MatrixXd whole_plan_outcome(const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                                     const PlanResult& planned, const v1::RenderIteration& it) const {
    if (it.refusal().empty()) return measured;
    return predicted_at_rest_points(mesh_, planned.final_state.x, it.capture().grid()) + (measured - predicted);
  }

  // The next iteration's targets; what changed, for people.
  std::string correct(const Eigen::MatrixXd& outcome, const v1::RenderIteration& it) {
    if (setup_.correction == v1::RENDER_CORRECTION_NONE) return "none (open loop: the same targets again)";
    std::ostringstream s;
    s.precision(3);
    if (calibration_.fitted()) {
      s << "plan with the fitted model (RMSE " << last_model_.rmse_mm() << " mm on the probe's "
        << last_model_.captures() << " captures):";
      for (const auto& p : last_model_.parameters()) s << " " << p.name() << " " << p.value();
    }
    // A run planned with the model before this fit: its error is the old
    // model's, which the fit has corrected, not the next plan's to learn.
    targets_moved_ = learns_targets(setup_.correction) && !it.has_model();
    if (it.has_model()) expectation_.model_refitted();
    if (learns_targets(setup_.correction) && !targets_moved_) s << "; targets kept (the model was refitted)";
    if (targets_moved_) {
      const Eigen::MatrixXd next = learned_targets(targets_, setup_.goal_mm, outcome, setup_.gain);
      const Eigen::ArrayXXd change = (next - targets_).array().abs();
      targets_ = next;
      if (calibration_.fitted()) s << "; ";
      s << "targets += " << setup_.gain << " x (goal - "
        << (it.refusal().empty() ? "measured" : "whole plan's prediction moved by the measured misfit")
        << "): mean |change| " << change.mean() << " mm, max "
        << change.maxCoeff() << " mm";
    }
    return s.str();
  }

  const RenderSetup& setup_;
  DeviceQueue& queue_;
  const Caller& caller_;
  const RenderHooks& hooks_;
  const Mesh mesh_;
  Eigen::MatrixXd targets_;
  // The best MAE against the goal so far; the last run's targets, to halve
  // a correction back towards; what the device is expected to make of a plan.
  double best_mae_ = INFINITY;
  Eigen::MatrixXd previous_targets_;
  RenderExpectation expectation_{mesh_, setup_.goal_mm};
  // The steps the device ran in the last iteration and in the best one.
  std::vector<Action> last_steps_, best_steps_;
  std::string screen_stop_;
  RenderCalibration calibration_;
  v1::FittedModel last_model_;
  bool device_shows_last_run_ = true;  // false after the probe, until a run
  bool targets_moved_ = false;         // by the last correction: the next plan is screened
  double pressure_limit_pa_ = INFINITY;  // learned from the device's refusals (learn_pressure_limit)
};

}  // namespace

v1::RenderResult run_render(const RenderSetup& setup, DeviceQueue& queue, const Caller& caller,
                            const RenderHooks& hooks) {
  return RenderRun(setup, queue, caller, hooks).run();
}

}  // namespace hj::server
