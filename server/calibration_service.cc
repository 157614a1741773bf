#include "calibration_service.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "calib/calibration_json.h"
#include "calib/diagnosis.h"
#include "calib/report/compare_report.h"
#include "calib/report/diagnose_report_html.h"
#include "calib/report/fit_report_html.h"
#include "calib/fit_model.h"
#include "calib/fit_parameters.h"
#include "dataset_upload.h"
#include "fitted_parameter_proto.h"
#include "request_context.h"
#include "service_error.h"
#include "streamed_work.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kDefaultSegments = 4;        // as the commands' --segments
constexpr int kDefaultMaxIterations = 20;  // as --max-iterations
constexpr int kMaxIterationsLimit = 1000;

using StageProgress = std::function<void(const std::string& stage, int done, int total, const std::string& detail)>;

// The library's work for one call: given the flag to poll and where to
// report progress, returns the result event.
template <class Event>
using Compute = std::function<Event(const std::function<bool()>& interrupted, const StageProgress& progress)>;

// Runs `compute` on the pool and relays its progress to `writer`, then its
// result (also returned in `last`). Stops the work when the caller cancels
// or the deadline (the caller's, or --max-calibration-seconds) passes (streamed_work.h).
template <class Event>
grpc::Status run_streamed(grpc::ServerContext* context, grpc::ServerWriter<Event>* writer, WorkPool& pool,
                          const ServerLimits& limits, Compute<Event> compute, const std::string& what, Event& last) {
  auto work =
      std::make_shared<StreamedWork<Event, Event>>(*context, limits.max_calibration_time, "--max-calibration-seconds");
  auto task = [work, what, compute = std::move(compute)] {
    if (work->should_stop()) return work->finish(work->stopped_status(what));
    try {
      const StageProgress progress = [&](const std::string& stage, int done, int total, const std::string& detail) {
        Event event;
        v1::CalibrationProgress* p = event.mutable_progress();
        p->set_stage(stage);
        p->set_done(done);
        p->set_total(total);
        p->set_detail(detail);
        if (const auto rmse = rmse_of_detail(detail)) p->set_rmse_mm(*rmse);
        work->push(std::move(event));
      };
      work->finish(grpc::Status::OK, compute([work] { return work->should_stop(); }, progress));
    } catch (const SettleInterrupted&) {
      work->finish(work->stopped_status(what));
    } catch (const SessionError& e) {
      // A replay that fails names the session and step: the data's problem.
      work->finish({grpc::StatusCode::INVALID_ARGUMENT, e.what()});
    } catch (...) {
      work->finish(status_from_current_exception());
    }
  };
  if (!pool.try_submit(std::move(task)))
    return {grpc::StatusCode::RESOURCE_EXHAUSTED,
            "work queue full: " + std::to_string(pool.workers()) + " workers busy and " +
                std::to_string(pool.queue_size()) + " requests waiting (--workers, --queue-size)"};
  const grpc::Status status = relay_until_done(context, writer, *work, what);
  if (!status.ok()) return status;
  last = std::move(work->result);
  if (!writer->Write(last)) return {grpc::StatusCode::CANCELLED, "the caller went away"};
  return grpc::Status::OK;
}

[[noreturn]] void refuse(const std::string& message) {
  throw ServiceError(grpc::StatusCode::INVALID_ARGUMENT, message);
}

// The replay options the request's options ask for (the commands'
// replay_options): segments, threads (at most --calibration-threads and the server's cores).
ReplayOptions replay_from(const v1::CalibrationOptions& o, const ServerLimits& limits) {
  ReplayOptions out;
  out.segments = o.segments() == 0 ? kDefaultSegments : o.segments();
  if (out.segments < 2 || out.segments > limits.max_segments)
    refuse("options.segments = " + std::to_string(o.segments()) + ": must be 2 .. " +
           std::to_string(limits.max_segments));
  if (o.threads() < 0) refuse("options.threads = " + std::to_string(o.threads()) + ": must be 0 (one per core) or more");
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  out.threads = calibration_thread_count(o.threads(), limits, cores);
  return out;
}

int max_iterations_from(const v1::CalibrationOptions& o) {
  if (o.max_iterations() == 0) return kDefaultMaxIterations;
  if (o.max_iterations() < 1 || o.max_iterations() > kMaxIterationsLimit)
    refuse("options.max_iterations = " + std::to_string(o.max_iterations()) + ": must be 1 .. " +
           std::to_string(kMaxIterationsLimit));
  return o.max_iterations();
}

// options.scale_mm: 0 means the command's default (5 mm).
double heat_map_scale(const v1::CalibrationOptions& o) {
  if (o.scale_mm() == 0.0) return 5.0;
  if (!(o.scale_mm() > 0.0) || !std::isfinite(o.scale_mm()))
    refuse("options.scale_mm = " + std::to_string(o.scale_mm()) + ": must be a positive number of mm");
  return o.scale_mm();
}

std::vector<std::string> list(const google::protobuf::RepeatedPtrField<std::string>& items) {
  return {items.begin(), items.end()};
}

// The model to start from, as the commands' start_params: params_json (its
// missing surface fields from the paper's defaults for this device) or the
// defaults, the device's pressure limit, `effects` switched on.
ModelParams start_model(const Dataset& dataset, const v1::CalibrationOptions& o, int segments,
                        const std::vector<std::string>& effects) {
  const SurfaceParameters defaults = SurfaceParameters::paper_defaults(dataset.device().geometry(segments));
  ModelParams params;
  params.surface = defaults;
  if (!o.params_json().empty()) {
    nlohmann::json doc;
    try {
      doc = nlohmann::json::parse(o.params_json());
    } catch (const nlohmann::json::parse_error& e) {
      refuse("options.params_json: invalid JSON at byte " + std::to_string(e.byte));
    }
    params = parse_model_params(doc, defaults, "options.params_json");
  }
  params.surface.max_pressure_pa = dataset.device().max_pressure_kpa * 1000.0;
  for (const auto& e : effects) EffectRegistry::instance().get(e);  // names the known effects if unknown
  return with_effects(params, effects);
}

// The sessions of `dataset` named in `names` (keep) or the others; an
// unknown name is the caller's mistake.
Dataset sessions_named(const Dataset& dataset, const std::vector<std::string>& names, bool keep) {
  try {
    return select_sessions(dataset, names, keep);
  } catch (const SessionError& e) {
    refuse(std::string("holdout: ") + e.what());
  }
}

void add_parameters(const LeastSquaresResult& fit, google::protobuf::RepeatedPtrField<v1::FittedParameter>* out) {
  for (const auto& e : fit.estimates) estimate_to_proto(e, out->Add());
}

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void note_upload(RequestContext& rc, const Dataset& dataset, size_t bytes) {
  rc.note("dataset", dataset.dir.string());
  rc.note("sessions", dataset.sessions.size());
  rc.note("captures", dataset.capture_count());
  rc.note("request_bytes", bytes);
}

}  // namespace

grpc::Status CalibrationServiceImpl::Compare(grpc::ServerContext* context, const v1::CompareRequest* request,
                                             grpc::ServerWriter<v1::CompareEvent>* writer) {
  RequestContext rc(context, "Compare");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "Compare");
    auto dataset = std::make_shared<const Dataset>(dataset_from_upload(request->dataset(), limits_));
    note_upload(rc, *dataset, request->ByteSizeLong());
    const ReplayOptions replay = replay_from(request->options(), limits_);
    const ModelParams params = start_model(*dataset, request->options(), replay.segments, list(request->options().effects()));
    const double scale_mm = heat_map_scale(request->options());
    Compute<v1::CompareEvent> compute = [dataset, params, replay, scale_mm](const std::function<bool()>& interrupted,
                                                                            const StageProgress& progress) {
      const auto start = Clock::now();
      ReplayOptions options = replay;
      options.interrupted = interrupted;
      const Evaluation evaluation =
          evaluate_dataset(*dataset, params, options, [&](int done, int total, const std::string& session) {
            progress("compare", done, total, session);
          });
      const CompareReport report =
          compare_report(*dataset, params, evaluation, scale_mm, [&](int done, int total, const std::string& path) {
            progress("heat maps", done, total, path);
          });
      v1::CompareEvent event;
      v1::CompareResult* r = event.mutable_result();
      r->set_summary_json(report.summary.dump(2));
      r->set_report_html(report.html);
      for (const ReportFile& map : report.maps) {
        v1::SessionFile* file = r->add_maps();
        file->set_path(map.path);
        file->set_content(map.bytes);
      }
      r->set_rmse_mm(evaluation.rmse_mm());
      r->set_mae_mm(evaluation.mae_mm());
      r->set_samples(evaluation.samples);
      r->set_noise_floor_mm(noise_floor_mm(*dataset));
      r->set_seconds(seconds_since(start));
      return event;
    };
    v1::CompareEvent last;
    const grpc::Status status = run_streamed(context, writer, pool_, limits_, std::move(compute), "the comparison", last);
    if (!status.ok()) throw ServiceError(status.error_code(), status.error_message());
    rc.note("rmse_mm", last.result().rmse_mm());
  });
}

grpc::Status CalibrationServiceImpl::Fit(grpc::ServerContext* context, const v1::FitRequest* request,
                                         grpc::ServerWriter<v1::FitEvent>* writer) {
  RequestContext rc(context, "Fit");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kOperator, "Fit");
    auto all = std::make_shared<const Dataset>(dataset_from_upload(request->dataset(), limits_));
    note_upload(rc, *all, request->ByteSizeLong());
    const std::vector<std::string> holdout = list(request->holdout());
    auto train = std::make_shared<const Dataset>(sessions_named(*all, holdout, false));
    auto held = std::make_shared<const Dataset>(sessions_named(*all, holdout, true));
    if (train->sessions.empty()) refuse("holdout leaves no session to fit");
    FitOptions options;
    options.initial_estimates = !request->no_initial();
    options.least_squares.max_iterations = max_iterations_from(request->options());
    options.least_squares.replay = fitting_replay(replay_from(request->options(), limits_));
    options.profile_loose = true;
    options.profile_also = list(request->profile());
    const ModelParams start = start_model(*all, request->options(), options.least_squares.replay.segments,
                                          list(request->options().effects()));
    Compute<v1::FitEvent> compute = [all, train, held, holdout, options, start](
                                        const std::function<bool()>& interrupted, const StageProgress& progress) {
      const auto t0 = Clock::now();
      FitOptions o = options;
      o.least_squares.replay.interrupted = interrupted;
      o.bisection.replay = o.least_squares.replay;
      const FitReport report = fit_model(*train, start, start.effects, o, progress);
      const nlohmann::json heldout =
          heldout_json(*held, holdout, report.joint.params, o.least_squares.replay,
                       [&](int done, int total, const std::string& session) {
                         progress("held-out sessions", done, total, session);
                       });
      const double seconds = seconds_since(t0);
      nlohmann::json extra = fit_extra_json(*all, report, heldout, all->dir.string());
      extra["seconds"] = seconds;
      v1::FitEvent event;
      v1::FitResult* r = event.mutable_result();
      r->set_params_json(model_params_json(report.joint.params, extra).dump(2));
      r->set_rmse_mm(report.joint.rmse_mm);
      r->set_r2(report.joint.r2);
      if (heldout.contains("rmse_mm")) r->set_heldout_rmse_mm(heldout["rmse_mm"].get<double>());
      add_parameters(report.joint, r->mutable_parameters());
      r->set_noise_floor_mm(noise_floor_mm(*all));
      r->set_seconds(seconds);
      r->set_report_html(fit_report_html(all->dir.filename().string(), report, heldout));
      return event;
    };
    v1::FitEvent last;
    const grpc::Status status = run_streamed(context, writer, pool_, limits_, std::move(compute), "the fit", last);
    if (!status.ok()) throw ServiceError(status.error_code(), status.error_message());
    rc.note("rmse_mm", last.result().rmse_mm());
  });
}

grpc::Status CalibrationServiceImpl::Diagnose(grpc::ServerContext* context, const v1::DiagnoseRequest* request,
                                              grpc::ServerWriter<v1::DiagnoseEvent>* writer) {
  RequestContext rc(context, "Diagnose");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kOperator, "Diagnose");
    auto dataset = std::make_shared<const Dataset>(dataset_from_upload(request->dataset(), limits_));
    note_upload(rc, *dataset, request->ByteSizeLong());
    DiagnoseOptions options;
    options.candidates = list(request->options().effects());
    for (const auto& e : options.candidates) EffectRegistry::instance().get(e);
    options.screening = !request->no_screening();
    options.fit.least_squares.max_iterations = max_iterations_from(request->options());
    options.fit.least_squares.replay = fitting_replay(replay_from(request->options(), limits_));
    // The baseline starts from params_json without its effects (the candidates are tried one by one).
    const ModelParams start =
        start_model(*dataset, request->options(), options.fit.least_squares.replay.segments, {});
    Compute<v1::DiagnoseEvent> compute = [dataset, options, start](const std::function<bool()>& interrupted,
                                                                   const StageProgress& progress) {
      const auto t0 = Clock::now();
      DiagnoseOptions o = options;
      o.fit.least_squares.replay.interrupted = interrupted;
      o.fit.bisection.replay = o.fit.least_squares.replay;
      const Diagnosis d = diagnose(*dataset, start, o, progress);
      const double seconds = seconds_since(t0);
      nlohmann::json doc = diagnosis_json(d);
      doc["seconds"] = seconds;
      v1::DiagnoseEvent event;
      v1::DiagnoseResult* r = event.mutable_result();
      r->set_diagnosis_json(doc.dump(2));
      r->set_params_json(model_params_json(d.final_params, {{"verdict", d.verdict}}).dump(2));
      for (const auto& e : d.verdict) r->add_verdict(e);
      r->set_baseline_rmse_mm(d.baseline.joint.rmse_mm);
      r->set_baseline_heldout_rmse_mm(d.baseline_heldout_rmse_mm);
      r->set_final_rmse_mm(d.ladder.empty() ? d.baseline.joint.rmse_mm : d.ladder.back().rmse_mm);
      r->set_final_heldout_rmse_mm(d.ladder.empty() ? d.baseline_heldout_rmse_mm : d.ladder.back().heldout_rmse_mm);
      add_parameters(d.baseline.joint, r->mutable_baseline_parameters());
      r->set_noise_floor_mm(d.noise_floor_mm);
      r->set_seconds(seconds);
      // Wall time only: the server's CPU clock counts every call it runs.
      r->set_report_html(diagnose_report_html(dataset->dir.filename().string(), d, o, DiagnoseRunTime{seconds, {}}));
      return event;
    };
    v1::DiagnoseEvent last;
    const grpc::Status status = run_streamed(context, writer, pool_, limits_, std::move(compute), "the diagnosis", last);
    if (!status.ok()) throw ServiceError(status.error_code(), status.error_message());
    rc.note("verdict", list(last.result().verdict()));
  });
}

}  // namespace hj::server
