#include "simulate_command.h"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>

#include "args.h"
#include "calib/frame_csv.h"
#include "calib/replay.h"
#include "demo_session.h"
#include "model_options.h"
#include "progress.h"

namespace hj::cli {

namespace {

const std::string kSimulateUsage = std::string(
    "usage: hapticjam simulate SESSION.json --out DIR [--mass KG] [--k N_PER_M]\n"
    "                          [--kappa-jam NM_PER_RAD] [--segments P] [--solver static|explicit]\n"
    "                          [--params FILE] [--effects A,B] [--set NAME=VALUE]\n"
    "Replays the steps of a measurement session (docs/session-format.md; its frames\n"
    "need not exist) and writes the predicted frame of every capture to DIR under the\n"
    "same relative name, on the session's sample grid (CSV, mm).\n"
    "  --mass KG            total membrane mass (default 0.55 kg per 12 cells; overrides --params)\n"
    "  --k N_PER_M          spring stiffness (default 64.5)\n"
    "  --kappa-jam NM_PER_RAD  jammed bending stiffness (default 4.79)\n"
    "  --segments P         segments per cell edge, >= 2 (default 4)\n"
    "  --solver NAME        static (default, Newton) or explicit (the paper's Euler)\n") +
                                   kModelOptionsUsage;

struct SimulateArgs {
  std::string session;
  std::string out;
  std::optional<double> mass_kg, spring_k, kappa_jam;
  ModelOptions model;
  int segments = 4;
  SolverKind solver = SolverKind::kStatic;
};

SimulateArgs parse_simulate_args(const std::vector<std::string>& args, bool need_session) {
  SimulateArgs out;
  for (ArgCursor cursor(args); cursor.next();) {
    const std::string& a = cursor.arg();
    auto value = [&]() -> const std::string& { return cursor.value(); };
    if (a == "--out") out.out = value();
    else if (a == "--mass") out.mass_kg = parse_number(a, value());
    else if (a == "--k") out.spring_k = parse_number(a, value());
    else if (a == "--kappa-jam") out.kappa_jam = parse_number(a, value());
    else if (a == "--segments") out.segments = parse_int(a, value(), 2, 1000);
    else if (a == "--solver") out.solver = parse_solver_kind(value());
    else if (out.model.parse(cursor)) continue;
    else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else if (need_session && out.session.empty()) out.session = a;
    else throw std::invalid_argument("unexpected argument \"" + a + "\"");
  }
  if (need_session && out.session.empty()) throw std::invalid_argument("missing SESSION.json");
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  return out;
}

int simulate(const SimulateArgs& args) {
  const Session session = read_session(args.session);
  const ModelParams model = args.model.resolve(SurfaceParameters::paper_defaults(session.device.geometry()));
  SurfaceParameters params = model.surface;
  if (args.mass_kg) params.mass_kg = *args.mass_kg;
  if (args.spring_k) params.spring_k = *args.spring_k;
  if (args.kappa_jam) params.kappa_jam = *args.kappa_jam;
  params.max_pressure_pa = session.device.max_pressure_kpa * 1000.0;
  params.validate();
  SimulatorOptions options;
  options.solver = args.solver;
  model.apply_to(options);
  if (!model.effects.empty()) {
    std::string on;
    for (const auto& name : model.effects) on += (on.empty() ? "" : ", ") + name;
    std::printf("effects on: %s\n", on.c_str());
  }

  const auto start = std::chrono::steady_clock::now();
  ProgressLine progress("simulate " + session.name);
  int settles = 0;
  long iterations = 0;
  const auto captures = replay_session(session, args.segments, params, options,
                                       [&](int done, int total, const SessionStep& step, const SettleReport& settle) {
                                         std::string what = step.kind == SessionStep::Kind::kCapture
                                                                ? "capture " + step.frame
                                                                : step.action.describe();
                                         if (step.kind == SessionStep::Kind::kAction) {
                                           ++settles;
                                           iterations += settle.iterations;
                                         }
                                         progress.update(done, total, what);
                                       });
  progress.finish();
  const std::filesystem::path out_dir(args.out);
  for (const auto& c : captures) write_frame_csv(out_dir / c.frame, c.heights_mm);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %d steps, %d settles (%ld %s iterations), %zu frames written to %s in %.2f s\n",
              session.name.c_str(), static_cast<int>(session.steps.size()), settles, iterations,
              args.solver == SolverKind::kStatic ? "Newton" : "Euler", captures.size(), out_dir.c_str(), seconds);
  return 0;
}

}  // namespace

int run_simulate(const std::vector<std::string>& args) {
  return run_subcommand<SimulateArgs>(
      "simulate", kSimulateUsage.c_str(), args, [](const std::vector<std::string>& a) { return parse_simulate_args(a, true); },
      simulate);
}

int run_demo(const std::vector<std::string>& args) {
  std::vector<std::string> with_default = args;
  bool has_out = false;
  for (const auto& a : args) has_out |= a == "--out";
  if (!has_out) with_default.insert(with_default.end(), {"--out", "hapticjam-demo"});
  SimulateArgs parsed;
  try {
    parsed = parse_simulate_args(with_default, false);
  } catch (const std::invalid_argument& e) {
    std::cerr << "hapticjam demo: " << e.what() << "\n";
    return 2;
  }
  // The output folder becomes a complete session: the steps and the frames.
  // A folder it cannot write to (a container's volume owned by another user)
  // is named here, not later as a session file that cannot be read.
  std::error_code ec;
  std::filesystem::create_directories(parsed.out, ec);
  if (ec) throw std::runtime_error(parsed.out + ": cannot create the output folder: " + ec.message());
  parsed.session = (std::filesystem::path(parsed.out) / "session.json").string();
  std::ofstream session_file(parsed.session);
  const std::string open_error = session_file ? "" : std::string(" (") + std::strerror(errno) + ")";
  session_file << kDemoSessionJson;
  session_file.close();
  if (!session_file)
    throw std::runtime_error(parsed.session + ": cannot write the demo session" + open_error +
                             ": is --out writable by this user?");
  return simulate(parsed);
}

}  // namespace hj::cli
