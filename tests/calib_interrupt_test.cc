// Interrupting the library's long work through ReplayOptions::interrupted
// (the server sets it when its caller cancels): compare, fit and diagnose
// end with SettleInterrupted wherever the interruption falls (levelling,
// Algorithm 1, least squares inside Ceres, profiles, candidates), never with
// a result made of interrupted replays taken for failed ones.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <memory>

#include "calib/diagnosis.h"
#include "calib/fit_model.h"
#include "calib/fit_parameters.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

// An unjammed sweep and a mixed session, on a coarse mesh: a short fit.
Dataset sessions() { return select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true); }

ReplayOptions coarse() {
  ReplayOptions r;
  r.segments = 2;
  return fitting_replay(r);
}

// Counts the polls (from every thread) and says "stop" after the first `after`.
struct Interrupter {
  explicit Interrupter(long after) : after(after) {}
  std::function<bool()> hook() {
    return [this] { return polls.fetch_add(1) >= after; };
  }
  long after;
  std::atomic<long> polls{0};
};

FitOptions fit_options(const std::function<bool()>& interrupted) {
  FitOptions o;
  o.least_squares.max_iterations = 4;
  o.least_squares.replay = coarse();
  o.least_squares.replay.interrupted = interrupted;
  o.bisection.replay = o.least_squares.replay;
  o.profile_loose = true;
  return o;
}

ModelParams start() {
  ModelParams p;
  p.surface = SurfaceParameters::paper_defaults(ArrayGeometry{3, 4, 0.038, 2});
  p.surface.max_pressure_pa = 3450.0;
  return p;
}

TEST(Interrupt, AComparisonStopsWithSettleInterrupted) {
  const Dataset d = sessions();
  for (long after : {0L, 40L}) {
    Interrupter stop(after);
    ReplayOptions r = coarse();
    r.interrupted = stop.hook();
    EXPECT_THROW(evaluate_dataset(d, start(), r), SettleInterrupted) << "after " << after << " polls";
  }
}

TEST(Interrupt, AFitStopsWithSettleInterruptedWhereverItFalls) {
  const Dataset d = sessions();
  Interrupter never(std::numeric_limits<long>::max());
  std::vector<std::string> stages;
  const FitReport whole = fit_model(d, start(), {}, fit_options(never.hook()),
                                    [&](const std::string& stage, int, int, const std::string&) {
                                      if (stages.empty() || stages.back() != stage) stages.push_back(stage);
                                    });
  EXPECT_GT(whole.joint.iterations, 0);
  const long total = never.polls;
  ASSERT_GT(total, 100);
  for (double share : {0.0, 0.1, 0.4, 0.7, 0.95}) {
    Interrupter stop(static_cast<long>(share * total));
    std::string stage_at_stop;
    EXPECT_THROW(fit_model(d, start(), {}, fit_options(stop.hook()),
                           [&](const std::string& stage, int, int, const std::string&) { stage_at_stop = stage; }),
                 SettleInterrupted)
        << "after " << share * 100 << " % of the polls, in \"" << stage_at_stop << "\"";
  }
}

// Inside Ceres the interruption is a failed evaluation and an aborted
// solve; the fit must still end with SettleInterrupted, not with the point
// where Ceres stopped.
TEST(Interrupt, ALeastSquaresFitStopsWithSettleInterruptedInsideCeres) {
  const Dataset d = sessions();
  const std::vector<FitParameter> parameters = fit_parameters({});
  Interrupter never(std::numeric_limits<long>::max());
  LeastSquaresOptions o = fit_options(never.hook()).least_squares;
  int iterations = 0;
  fit_least_squares(d, start(), parameters, o, [&](int iteration, int, double) { iterations = iteration; });
  ASSERT_GE(iterations, 2);
  const long total = never.polls;
  for (double share : {0.3, 0.6, 0.9}) {
    Interrupter stop(static_cast<long>(share * total));
    o.replay.interrupted = stop.hook();
    int reached = 0;
    EXPECT_THROW(fit_least_squares(d, start(), parameters, o, [&](int iteration, int, double) { reached = iteration; }),
                 SettleInterrupted)
        << "after " << share * 100 << " % of the polls, iteration " << reached;
  }
}

TEST(Interrupt, ADiagnosisStopsWithSettleInterrupted) {
  const Dataset d = sessions();
  DiagnoseOptions o;
  o.candidates = {"bending"};
  o.screening = false;
  o.fit = fit_options({});
  Interrupter never(std::numeric_limits<long>::max());
  o.fit.least_squares.replay.interrupted = o.fit.bisection.replay.interrupted = never.hook();
  const Diagnosis whole = diagnose(d, start(), o);
  ASSERT_EQ(whole.ranking.size(), 1u);
  const long total = never.polls;
  for (double share : {0.5, 0.9}) {  // the baseline's cross-validation; the candidate's refit
    Interrupter stop(static_cast<long>(share * total));
    o.fit.least_squares.replay.interrupted = o.fit.bisection.replay.interrupted = stop.hook();
    EXPECT_THROW(diagnose(d, start(), o), SettleInterrupted) << "after " << share * 100 << " % of the polls";
  }
}

}  // namespace
}  // namespace hj
