#include "sweep_command.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string_view>
#include <thread>

#include "args.h"
#include "plan/sweep.h"
#include "plot_png.h"
#include "progress.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"

namespace hj::cli {

namespace {

constexpr const char* kSweepUsage =
    "usage: hapticjam sweep GOAL... --out DIR [--sizes paper|RxC,RxC,...] [--planner NAME]\n"
    "                       [--jobs N] [--budget-s S] [--segments P] [--max-height-mm H]\n"
    "                       [--up-axis [-]x|y|z] [--view-resolution N] [--encoding E] [--no-sidecar]\n"
    "                       [--align [--align-pick cost|random]]\n"
    "Plans every GOAL at every array size, the plans in parallel (one thread each),\n"
    "and writes DIR/sweep.csv (goal, rows, cols, cells, correlation, the Laplace\n"
    "mean of the goal as resampled to the mesh for each alpha_L, steps, refused,\n"
    "relief_mm, seconds and of them the settles kept and refused, status, detail,\n"
    "the planner's note), DIR/table2.csv (line fit of correlation\n"
    "against the Laplace mean per alpha_L beside the paper's r^2, also printed),\n"
    "DIR/fig11_correlation_vs_cells.png and DIR/fig13_correlation_vs_laplace.png\n"
    "(at the alpha_L whose fit is best).\n"
    "  --sizes S           \"paper\" (default: the 16 sizes of Table 1, 1x2 .. 9x12), \"quick\"\n"
    "                      (2x2,3x4,4x6,6x8,9x12) or a list such as 2x2,3x4\n"
    "  --planner NAME      default portfolio (Algorithm 2 and three variants, the best kept)\n"
    "  --jobs N            threads (default: one per core)\n"
    "  --budget-s S        per plan; a plan past it is stopped at its next action and\n"
    "                      recorded as over-budget (default 120)\n"
    "  --segments P        segments per cell edge (default 4)\n"
    "  --max-height-mm H   goal height range on the display (default: 10 mm per cell\n"
    "                      of each array's shorter side)\n"
    "  --up-axis A         meshes' up axis (default: each mesh's sidecar JSON \"up_axis\", else z)\n"
    "  --view-resolution N pixels of a mesh's top view along its longer side (default 256)\n"
    "  --encoding E        PNG pixels: grey (default), terrain-rgb or terrarium\n"
    "  --no-sidecar        ignore NAME.json beside a goal (orientation, georef)\n"
    "  --align             plan each goal aligned (as plan --align): correlation is the\n"
    "                      aligned goal's; sweep.csv gains align_shift_x_cells,\n"
    "                      align_shift_y_cells, align_scale, unaligned_correlation,\n"
    "                      align_gain, unaligned_seconds and align_planned\n"
    "  --align-pick P      cost (default: the windows of lowest valley cost) or random\n"
    "                      (a control: as many windows at random, seeded); implies --align\n";
static_assert(std::string_view(kDefaultPlanner) == "portfolio", "kSweepUsage names the default planner");

struct SweepArgs {
  std::vector<std::string> goals;
  std::string out, up_axis;
  SweepOptions options;
  ImportOptions import;
};

std::pair<char, bool> parse_axis(const std::string& text) {
  std::string axis = text;
  const bool negative = !axis.empty() && axis[0] == '-';
  if (!axis.empty() && (axis[0] == '-' || axis[0] == '+')) axis.erase(0, 1);
  for (char& c : axis) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (axis != "x" && axis != "y" && axis != "z")
    throw std::invalid_argument("--up-axis needs x, y, z, -x, -y or -z, got \"" + text + "\"");
  return {axis[0], negative};
}

SweepArgs parse_sweep_args(const std::vector<std::string>& args) {
  SweepArgs out;
  for (ArgCursor cursor(args); cursor.next();) {
    const std::string& a = cursor.arg();
    auto value = [&]() -> const std::string& { return cursor.value(); };
    if (a == "--out") out.out = value();
    else if (a == "--sizes") out.options.sizes = parse_array_sizes(value());
    else if (a == "--planner") out.options.planner = value();
    else if (a == "--jobs") out.options.jobs = parse_int(a, value(), 1, 1024);
    else if (a == "--budget-s") {
      out.options.budget_s = parse_number(a, value());
      if (!(out.options.budget_s > 0.0)) throw std::invalid_argument("--budget-s needs a positive number of seconds");
    }
    else if (a == "--segments") out.options.segments = parse_int(a, value(), 2, 1000);
    else if (a == "--max-height-mm") {
      out.options.max_height_mm = parse_number(a, value());
      if (!(out.options.max_height_mm > 0.0)) throw std::invalid_argument("--max-height-mm needs a positive number (mm)");
    } else if (a == "--up-axis") {
      out.up_axis = value();
      (void)parse_axis(out.up_axis);
    } else if (a == "--view-resolution") out.import.mesh_resolution = parse_int(a, value(), 1, 8192);
    else if (a == "--encoding") out.import.encoding = parse_pixel_encoding(value());
    else if (a == "--no-sidecar") out.import.sidecar = false;
    else if (a == "--align") {
      if (!out.options.align) out.options.align = AlignedPlanOptions{};
    } else if (a == "--align-pick") {
      const std::string pick = value();
      if (pick != "cost" && pick != "random")
        throw std::invalid_argument("--align-pick needs cost or random, got \"" + pick + "\"");
      if (!out.options.align) out.options.align = AlignedPlanOptions{};
      out.options.align->pick = pick == "random" ? AlignedPlanOptions::Pick::kRandom : AlignedPlanOptions::Pick::kValleyCost;
    }
    else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else out.goals.push_back(a);
  }
  if (out.goals.empty()) throw std::invalid_argument("missing GOAL (one or more)");
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  return out;
}

bool is_mesh(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const char* m : {".3mf", ".glb", ".gltf", ".obj", ".ply", ".stl"})
    if (ext == m) return true;
  return false;
}

// A mesh's up axis: --up-axis, else the importer's default (its sidecar's "up_axis", else z).
ImportOptions import_options_for(const std::filesystem::path& goal, const SweepArgs& args) {
  ImportOptions o = args.import;
  if (is_mesh(goal) && !args.up_axis.empty()) std::tie(o.mesh_up_axis, o.mesh_up_negative) = parse_axis(args.up_axis);
  return o;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

std::string alpha_name(double a) {
  // Column-name friendly: 0, 1/8, 1/4, 1/2, 1 -> a0, a1_8, a1_4, a1_2, a1; others by value.
  for (int d : {1, 2, 3, 4, 6, 8})
    for (int n = 0; n <= d; ++n)
      if (std::abs(a - double(n) / d) < 1e-12) return n == 0 ? "a0" : n == d ? "a1" : "a" + std::to_string(n) + "_" + std::to_string(d);
  std::ostringstream s;
  s << "a" << a;
  return s.str();
}

int sweep(const SweepArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  args.options.validate();
  std::vector<SweepGoal> goals;
  for (const auto& g : args.goals) {
    const std::filesystem::path file(g);
    goals.push_back({file.stem().string(), import_goal(file, import_options_for(file, args))});
  }
  const int jobs = args.options.jobs > 0 ? args.options.jobs : int(std::max(1u, std::thread::hardware_concurrency()));
  std::fprintf(stderr, "sweep: %zu goal(s) x %zu size(s) on %d thread(s), budget %g s per plan\n", goals.size(),
               args.options.sizes.size(), jobs, args.options.budget_s);
  ProgressLine progress("sweep");
  const auto rows = run_sweep(goals, args.options, [&](int done, int total, const SweepRow& r) {
    std::ostringstream what;
    what << r.goal << " " << r.rows << "x" << r.cols << " " << r.status << " " << std::fixed << std::setprecision(1)
         << r.seconds << " s";
    progress.update(done, total, what.str());
  });
  progress.finish();

  const std::filesystem::path out(args.out);
  std::filesystem::create_directories(out);
  const auto& alphas = args.options.alphas;
  {
    std::ofstream csv(out / "sweep.csv");
    csv << "goal,rows,cols,cells,correlation";
    for (double a : alphas) csv << ",laplace_mean_" << alpha_name(a);
    csv << ",steps,refused,relief_mm,seconds,settle_seconds,refused_seconds,status,detail,note";
    if (args.options.align)
      csv << ",align_shift_x_cells,align_shift_y_cells,align_scale,unaligned_correlation,align_gain,unaligned_seconds,"
             "align_planned";
    csv << "\n" << std::setprecision(6);
    for (const auto& r : rows) {
      csv << csv_field(r.goal) << "," << r.rows << "," << r.cols << "," << r.cells() << ",";
      if (r.correlation) csv << *r.correlation;
      for (std::size_t k = 0; k < alphas.size(); ++k) {
        csv << ",";
        if (k < r.laplace_mean.size()) csv << r.laplace_mean[k];
      }
      csv << "," << r.steps << "," << r.refused << "," << r.relief_mm << "," << r.seconds << "," << r.settle_seconds
          << "," << r.refused_seconds << "," << r.status << "," << csv_field(r.detail) << "," << csv_field(r.note);
      if (args.options.align) {
        csv << ",";
        if (r.align) {
          const GoalTransform& t = r.align->transform;
          csv << t.shift_x_cells << "," << t.shift_y_cells << "," << t.scale << ",";
          if (r.align->unaligned_correlation) csv << *r.align->unaligned_correlation;
          csv << ",";
          if (r.align->unaligned_correlation && r.correlation) csv << *r.correlation - *r.align->unaligned_correlation;
          csv << "," << r.align->unaligned_seconds << "," << r.align->planned;
        } else {
          csv << ",,,,,,";
        }
      }
      csv << "\n";
    }
  }
  const auto t2 = table2(rows, alphas);
  {
    std::ofstream csv(out / "table2.csv");
    csv << "alpha_l,slope,intercept,r2,n,paper_r2\n" << std::setprecision(6);
    for (const auto& t : t2) {
      csv << t.alpha << ",";
      if (t.fit) csv << t.fit->slope << "," << t.fit->intercept << "," << t.fit->r2 << "," << t.fit->n;
      else csv << ",,,0";
      csv << ",";
      if (const auto paper = paper_table2_r2(t.alpha)) csv << *paper;
      csv << "\n";
    }
  }

  // Fig. 11: correlation against the number of cells, one line per goal.
  Plot fig11;
  fig11.title = "Correlation against array size (cf. Fig. 11)";
  fig11.x_label = "number of cells";
  fig11.y_label = "correlation (Eq. 12)";
  std::map<std::string, std::size_t> index;
  for (const auto& r : rows) {
    if (!index.count(r.goal)) index[r.goal] = fig11.series.size(), fig11.series.emplace_back().name = r.goal;
    if (r.correlation) {
      fig11.series[index[r.goal]].x.push_back(double(r.cells()));
      fig11.series[index[r.goal]].y.push_back(*r.correlation);
    }
  }
  write_plot_png(out / "fig11_correlation_vs_cells.png", fig11);
  // Fig. 13: correlation against the Laplace mean at the alpha_L whose line
  // fit is best (highest r^2), with the fit.
  std::size_t a13 = 0;
  for (std::size_t k = 0; k < alphas.size() && k < t2.size(); ++k)
    if (t2[k].fit && (!t2[a13].fit || t2[k].fit->r2 > t2[a13].fit->r2)) a13 = k;
  Plot fig13;
  fig13.title = "Correlation against the Laplace mean (cf. Fig. 13)";
  fig13.x_label = "Laplace mean of the goal on the mesh";
  fig13.y_label = "correlation (Eq. 12)";
  for (const auto& s : fig11.series) {
    PlotSeries& points = fig13.series.emplace_back();
    points.name = s.name;
    points.lines = false;
  }
  for (const auto& r : rows)
    if (r.correlation && a13 < r.laplace_mean.size()) {
      fig13.series[index[r.goal]].x.push_back(r.laplace_mean[a13]);
      fig13.series[index[r.goal]].y.push_back(*r.correlation);
    }
  if (a13 < t2.size() && t2[a13].fit) {
    char label[96];
    std::snprintf(label, sizeof label, "fit: r = %.3f L %+.3f, r^2 = %.3f (alpha_L = %.3g)", t2[a13].fit->slope,
                  t2[a13].fit->intercept, t2[a13].fit->r2, alphas[a13]);
    fig13.fits.push_back({t2[a13].fit->slope, t2[a13].fit->intercept, label});
  }
  write_plot_png(out / "fig13_correlation_vs_laplace.png", fig13);

  // The table on stdout.
  std::printf("%-28s %5s %5s %6s %11s %9s %8s  %s\n", "goal", "rows", "cols", "cells", "correlation", "laplace", "seconds", "status");
  for (const auto& r : rows)
    std::printf("%-28.28s %5d %5d %6d %11s %9.4f %8.2f  %s%s\n", r.goal.c_str(), r.rows, r.cols, r.cells(),
                r.correlation ? std::to_string(*r.correlation).substr(0, 6).c_str() : "-",
                a13 < r.laplace_mean.size() ? r.laplace_mean[a13] : NAN, r.seconds, r.status.c_str(),
                r.detail.empty() ? "" : (" (" + r.detail.substr(0, 80) + ")").c_str());
  std::printf("\nTable 2 analogue: correlation = slope * Laplace mean + intercept\n%-8s %9s %10s %7s %4s %10s\n",
              "alpha_L", "slope", "intercept", "r^2", "n", "paper r^2");
  for (const auto& t : t2) {
    const std::optional<double> paper = paper_table2_r2(t.alpha);
    const std::string paper_text = paper ? std::to_string(*paper).substr(0, 6) : "-";
    if (t.fit)
      std::printf("%-8.4g %9.4f %10.4f %7.4f %4d %10s\n", t.alpha, t.fit->slope, t.fit->intercept, t.fit->r2, t.fit->n,
                  paper_text.c_str());
    else
      std::printf("%-8.4g %9s %10s %7s %4d %10s\n", t.alpha, "-", "-", "-", 0, paper_text.c_str());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("\n%zu plans in %.1f s; written to %s\n", rows.size(), seconds, args.out.c_str());
  return 0;
}

}  // namespace

int run_sweep_command(const std::vector<std::string>& args) {
  return run_subcommand<SweepArgs>("sweep", kSweepUsage, args, parse_sweep_args, sweep);
}

}  // namespace hj::cli
