#include "plan_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string_view>
#include <nlohmann/json.hpp>
#include <optional>

#include "args.h"
#include "calib/frame_csv.h"
#include "calib/step_json.h"
#include "compare_image.h"
#include "metrics/correlation.h"
#include "metrics/error_breakdown.h"
#include "metrics/laplace_predictor.h"
#include "plan/aligned_plan.h"
#include "plan/aligned_plan_json.h"
#include "plan/default_planner.h"
#include "plan/planner.h"
#include "plan/refused_json.h"
#include "progress.h"
#include "shapes/geo_region.h"
#include "shapes/goal_importer.h"
#include "shapes/region.h"
#include "shapes/resample.h"
#include "sim/surface_measures.h"

namespace hj::cli {

namespace {

constexpr const char* kPlanUsage =
    "usage: hapticjam plan GOAL --rows R --cols C --out DIR [--segments P] [--planner NAME]\n"
    "                      [--max-height-mm H | --heights absolute] [--region x0,y0,x1,y1] [--hue] [--json]\n"
    "                      [--up-axis [-]x|y|z] [--view-resolution N]\n"
    "                      [--region-lonlat lon0,lat0,lon1,lat1] [--encoding E] [--no-sidecar] [--align]\n"
    "                      [--levelling-margin M]\n"
    "Plans the actions that make the display show GOAL (a height image: CSV, PNG,\n"
    "TIFF or GeoTIFF, SRTM .hgt; or a mesh: STL, OBJ, PLY, glTF/GLB, 3MF, seen from\n"
    "above) and writes DIR/plan.json (steps in the session format, correlation,\n"
    "Laplace mean, and the actions refused as dead ends with their reasons),\n"
    "DIR/predicted.csv and DIR/goal.csv (mm per mesh point, row i along +y),\n"
    "DIR/predicted_x.csv and predicted_y.csv (in-plane positions, mm) and DIR/compare.png.\n"
    "  --rows R, --cols C    array size in cells (38 mm cells)\n"
    "  --segments P          segments per cell edge (default 4)\n"
    "  --planner NAME        default portfolio (Algorithm 2 and three variants, the best kept)\n"
    "  --max-height-mm H     goal height range on the display (default: 10 mm per cell\n"
    "                        of the array's shorter side, e.g. 30 mm at 3 x 4, 90 mm at 9 x 12)\n"
    "  --heights H           scaled (default: stretched to --max-height-mm) or absolute:\n"
    "                        a CSV or float TIFF taken as mm above the clamped edge's\n"
    "                        plane (negative allowed); (R p + 1) x (C p + 1) values are\n"
    "                        the goal at the mesh points (docs/goals.md)\n"
    "  --region x0,y0,x1,y1  zoom: pixels, or fractions of the image if all <= 1\n"
    "  --hue                 colour topographic map: red-orange high, blue-purple low\n"
    "  --json                print the summary as JSON\n"
    "  --up-axis A           a mesh's up axis: x, y, z, -x, -y or -z (default: its sidecar's\n"
    "                        \"up_axis\", else z)\n"
    "  --view-resolution N   pixels of a mesh's top view along its longer side (default 256)\n"
    "  --region-lonlat B     zoom a georeferenced goal (GeoTIFF, .hgt, CSV with a sidecar\n"
    "                        georef) to west,south,east,north in degrees (WGS 84)\n"
    "  --encoding E          PNG pixels: grey (default), terrain-rgb (Mapbox) or terrarium\n"
    "  --no-sidecar          ignore NAME.json beside the goal (it turns DEMs north-up)\n"
    "  --align               shift the goal's window by up to half a cell and scale it to\n"
    "                        0.8..1 of its side so its valleys fall on nodes; plans the\n"
    "                        unaligned goal and the best few candidates and keeps the best\n"
    "                        (plan.json \"align\": transform and gain; docs/planners.md)\n"
    "  --levelling-margin M  for a device: algorithm2-levelled (alone or in the portfolio)\n"
    "                        acts only from M x the levelling pressure, 1 to 4 (default 1;\n"
    "                        a render plans with 1.5; docs/planners.md)\n";
static_assert(std::string_view(kDefaultPlanner) == "portfolio", "kPlanUsage names the default planner");

struct PlanArgs {
  std::string goal, out, planner = kDefaultPlanner, region, region_lonlat;
  int rows = 0, cols = 0, segments = 4;
  double max_height_mm = 0.0;  // 0: the array's default relief (default_relief_mm)
  double levelling_margin = 1.0;
  bool hue = false, json = false, align = false;
  GoalHeights heights = GoalHeights::kScaled;
  ImportOptions import;
};

PlanArgs parse_plan_args(const std::vector<std::string>& args) {
  PlanArgs out;
  for (ArgCursor cursor(args); cursor.next();) {
    const std::string& a = cursor.arg();
    auto value = [&]() -> const std::string& { return cursor.value(); };
    if (a == "--out") out.out = value();
    else if (a == "--rows") out.rows = parse_int(a, value(), 1, 1000);
    else if (a == "--cols") out.cols = parse_int(a, value(), 1, 1000);
    else if (a == "--segments") out.segments = parse_int(a, value(), 2, 1000);
    else if (a == "--planner") out.planner = value();
    else if (a == "--region") out.region = value();
    else if (a == "--region-lonlat") out.region_lonlat = value(), (void)parse_lonlat_box(out.region_lonlat);
    else if (a == "--encoding") out.import.encoding = parse_pixel_encoding(value());
    else if (a == "--no-sidecar") out.import.sidecar = false;
    else if (a == "--hue") out.hue = true;
    else if (a == "--view-resolution") out.import.mesh_resolution = parse_int(a, value(), 1, 8192);
    else if (a == "--up-axis") {
      std::string axis = value();
      out.import.mesh_up_negative = !axis.empty() && axis[0] == '-';
      if (out.import.mesh_up_negative) axis.erase(0, 1);
      if (axis != "x" && axis != "y" && axis != "z")
        throw std::invalid_argument("--up-axis needs x, y, z, -x, -y or -z, got \"" + axis + "\"");
      out.import.mesh_up_axis = axis[0];
    }
    else if (a == "--json") out.json = true;
    else if (a == "--align") out.align = true;
    else if (a == "--levelling-margin") out.levelling_margin = parse_number(a, value());
    else if (a == "--heights") out.heights = parse_goal_heights(value());
    else if (a == "--max-height-mm") {
      out.max_height_mm = parse_number(a, value());
      if (!(out.max_height_mm > 0.0)) throw std::invalid_argument("--max-height-mm needs a positive number (mm)");
    } else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else if (out.goal.empty()) out.goal = a;
    else throw std::invalid_argument("unexpected argument \"" + a + "\"");
  }
  if (out.goal.empty()) throw std::invalid_argument("missing GOAL");
  if (out.rows == 0 || out.cols == 0) throw std::invalid_argument("--rows and --cols are required");
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  if (!out.region.empty() && !out.region_lonlat.empty())
    throw std::invalid_argument("--region and --region-lonlat exclude each other");
  if (out.hue && out.import.encoding != PixelEncoding::kGrey)
    throw std::invalid_argument("--hue and --encoding exclude each other");
  if (out.heights == GoalHeights::kAbsolute) {
    if (out.max_height_mm > 0.0) throw std::invalid_argument("--heights absolute and --max-height-mm exclude each other");
    check_absolute_goal_format(out.goal);
    if (out.align)
      throw std::invalid_argument("--align and --heights absolute exclude each other: absolute heights are the "
                                  "surface the user asked for, at the mesh points, not a window to move");
  }
  return out;
}

// Where the remaining error lies (metrics/error_breakdown.h).
nlohmann::json error_breakdown_to_json(const ErrorBreakdown& b) {
  nlohmann::json places = nlohmann::json::object();
  for (const ErrorPlace& p : b.places)
    places[p.name] = {{"error_share", p.error_share}, {"area_share", p.area_share}, {"rms_mm", p.rms_mm}};
  return {{"rms_mm", b.rms_mm}, {"dominant", b.dominant()}, {"places", places}};
}

// Mesh point heights (row i along +y) as an image (row 0 at the top).
Eigen::MatrixXd as_image(const Eigen::MatrixXd& points) { return points.colwise().reverse(); }

// The pixels of the imported goal the region options take (all of it without one).
Region goal_window(const HeightMap& imported, const PlanArgs& args) {
  if (!args.region.empty()) return pixel_region(parse_region(args.region), imported.z.rows(), imported.z.cols());
  if (!args.region_lonlat.empty()) return lonlat_pixel_region(imported, parse_lonlat_box(args.region_lonlat));
  return Region{0.0, 0.0, double(imported.z.cols()), double(imported.z.rows()), false};
}

int plan(const PlanArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  ImportOptions import = args.import;
  import.hue = args.hue;
  const HeightMap imported = import_goal(args.goal, import);
  HeightMap goal = imported;
  if (!args.region.empty()) goal = crop(goal, parse_region(args.region));
  if (!args.region_lonlat.empty()) goal = crop_lonlat(goal, parse_lonlat_box(args.region_lonlat));
  const ArrayGeometry geometry{args.rows, args.cols, 0.038, args.segments};
  const Mesh mesh(geometry);
  PlanRequest request{geometry, SurfaceParameters::paper_defaults(geometry),
                      goal_to_mesh(goal, mesh, args.heights, args.max_height_mm), {}, goal.z};
  const bool absolute = args.heights == GoalHeights::kAbsolute;
  if (absolute) request.scoring = PlanScoring::kHeightError;
  request.levelling_margin = args.levelling_margin;
  const double relief_mm = absolute ? request.goal_mm.maxCoeff() - request.goal_mm.minCoeff()
                                    : relief_or_default_mm(args.max_height_mm, geometry);
  const auto planner = make_planner(args.planner);

  ProgressLine progress("plan " + std::filesystem::path(args.goal).filename().string());
  PlanCallbacks callbacks;
  callbacks.progress = [&](double fraction, const std::string& what) {
    progress.update(static_cast<int>(std::lround(fraction * 100)), 100, what);
  };
  std::optional<AlignedPlan> aligned;
  PlanResult result;
  if (args.align) {
    // The aligned goal replaces the unaligned one in everything written below.
    aligned = plan_aligned(args.planner, imported, goal_window(imported, args), request, relief_mm, {}, callbacks);
    goal = aligned->goal;
    request.goal_mm = aligned->chosen.goal_mm;
    request.goal_image = goal.z;
    result = std::move(aligned->result);
  } else {
    result = planner->plan(request, callbacks);
  }
  progress.finish();

  const Eigen::MatrixXd predicted_mm = point_heights(mesh, result.final_state.x) * 1000.0;
  const Correlation corr = correlate_with_goal(goal.z, as_image(predicted_mm));
  const double laplace = laplace_mean(goal.z);

  const std::filesystem::path out(args.out);
  std::filesystem::create_directories(out);
  write_frame_csv(out / "predicted.csv", predicted_mm);
  // The in-plane positions too, so a capture is compared where the points moved (remote submit --capture).
  write_frame_csv(out / "predicted_x.csv", point_coordinates(mesh, result.final_state.x, 0) * 1000.0);
  write_frame_csv(out / "predicted_y.csv", point_coordinates(mesh, result.final_state.x, 1) * 1000.0);
  write_frame_csv(out / "goal.csv", request.goal_mm);
  write_compare_png(out / "compare.png", mesh, request.goal_mm, predicted_mm);
  nlohmann::json steps = nlohmann::json::array();
  for (const Action& a : result.steps) steps.push_back(action_to_step_json(a));
  const SurfaceParameters& p = request.params;
  nlohmann::json doc = {
      {"format", "hapticjam.plan/1"},
      {"goal", args.goal},
      {"array", {{"rows", args.rows}, {"cols", args.cols}, {"cell_size_mm", 38.0}, {"segments", args.segments}}},
      {"parameters",
       {{"mass_kg", p.mass_kg}, {"spring_k", p.spring_k}, {"kappa_jam", p.kappa_jam}, {"max_pressure_kpa", p.max_pressure_pa / 1000.0}}},
      {"planner", planner->name()},
      {"max_height_mm", relief_mm},
      {"heights", absolute ? "absolute" : "scaled"},
      {"steps", steps},
      {"correlation", corr.value ? nlohmann::json(*corr.value) : nlohmann::json(nullptr)},
      {"laplace_mean", laplace}};
  if (!corr.value) doc["correlation_undefined"] = corr.undefined_reason;
  if (!result.note.empty()) doc["planner_note"] = result.note;
  if (aligned) doc["align"] = aligned_plan_to_json(*aligned);
  doc["refused"] = refused_to_json(result.refused);
  doc["error_breakdown"] = error_breakdown_to_json(error_breakdown(mesh, request.goal_mm, predicted_mm));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Where the time went: the settles kept, the dead ends refused, the rest (import, rest state, files).
  doc["seconds"] = {{"total", seconds}, {"settles_kept", result.settle_seconds}, {"settles_refused", result.refused_seconds}};
  std::ofstream(out / "plan.json") << doc.dump(1) << "\n";
  if (args.json) {
    nlohmann::json summary = {{"goal", args.goal}, {"rows", args.rows}, {"cols", args.cols},
                              {"steps", result.steps.size()}, {"refused", result.refused.size()},
                              {"correlation", doc["correlation"]},
                              {"laplace_mean", laplace}, {"seconds", seconds},
                              {"refused_seconds", result.refused_seconds}, {"out", args.out}};
    if (aligned) summary["align"] = aligned_plan_to_json(*aligned, false);
    std::cout << summary.dump() << "\n";
  } else {
    std::printf("%s on %d x %d: %zu steps%s, correlation %s, Laplace mean %.3f, written to %s in %.2f s\n",
                args.goal.c_str(), args.rows, args.cols, result.steps.size(),
                result.refused.empty() ? ""
                                       : (" (" + std::to_string(result.refused.size()) +
                                          " actions refused as dead ends, see plan.json)").c_str(),
                corr.value ? std::to_string(*corr.value).substr(0, 6).c_str() : ("undefined (" + corr.undefined_reason + ")").c_str(),
                laplace, args.out.c_str(), seconds);
    if (aligned)
      std::printf("aligned: window shifted %+.3f, %+.3f cells, scaled %.3f; correlation %.4f against %.4f unaligned "
                  "(gain %+.4f), %zu goals planned of %d candidates\n",
                  aligned->chosen.transform.shift_x_cells, aligned->chosen.transform.shift_y_cells,
                  aligned->chosen.transform.scale, aligned->score, aligned->unaligned_score, aligned->gain(),
                  aligned->planned.size(), aligned->candidates);
  }
  return 0;
}

}  // namespace

int run_plan(const std::vector<std::string>& args) {
  return run_subcommand<PlanArgs>("plan", kPlanUsage, args, parse_plan_args, plan);
}

}  // namespace hj::cli
