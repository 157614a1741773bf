#include "proto_convert.h"

#include <cmath>
#include <stdexcept>

#include "calib/model_params.h"
#include "shapes/resample.h"
#include "sim/surface_measures.h"

namespace hj::server {

namespace {

void check_count(const char* field, long value, long limit) {
  if (value > limit)
    throw std::invalid_argument(std::string(field) + " " + std::to_string(value) + " is over the server's limit of " +
                                std::to_string(limit));
}

}  // namespace

ArrayConfig array_from_proto(const v1::ArraySpec& spec, const ServerLimits& limits) {
  if (spec.rows() < 1 || spec.cols() < 1)
    throw std::invalid_argument("array.rows and array.cols must be at least 1, got " + std::to_string(spec.rows()) +
                                " x " + std::to_string(spec.cols()));
  check_count("array.rows", spec.rows(), limits.max_array_side_cells);
  check_count("array.cols", spec.cols(), limits.max_array_side_cells);
  if (spec.segments() < 0 || spec.segments() == 1)
    throw std::invalid_argument("array.segments must be at least 2 (0 = 4), got " + std::to_string(spec.segments()));
  check_count("array.segments", spec.segments(), limits.max_segments);
  if (!(spec.cell_size_mm() >= 0.0) || !std::isfinite(spec.cell_size_mm()))
    throw std::invalid_argument("array.cell_size_mm must be positive (0 = 38 mm)");

  ArrayConfig out;
  out.geometry = {spec.rows(), spec.cols(), spec.cell_size_mm() > 0.0 ? spec.cell_size_mm() / 1000.0 : 0.038,
                  spec.segments() > 0 ? spec.segments() : 4};
  const long points = long(out.geometry.rows * out.geometry.segments + 1) * (out.geometry.cols * out.geometry.segments + 1);
  check_count("mesh points (rows*segments+1)*(cols*segments+1)", points, limits.max_mesh_points);

  // The parameters: as a params document, so the library's parser names a bad key.
  const v1::SurfaceParameters& p = spec.parameters();
  nlohmann::json surface = nlohmann::json::object();
  if (p.has_mass_kg()) surface["mass_kg"] = p.mass_kg();
  if (p.has_spring_k()) surface["spring_k"] = p.spring_k();
  if (p.has_damping_b()) surface["damping_b"] = p.damping_b();
  if (p.has_kappa_jam()) surface["kappa_jam"] = p.kappa_jam();
  if (p.has_gravity()) surface["gravity"] = p.gravity();
  if (p.has_max_pressure_pa()) surface["max_pressure_pa"] = p.max_pressure_pa();
  nlohmann::json effects = nlohmann::json::object();
  for (const v1::Effect& e : p.effects()) {
    nlohmann::json values = nlohmann::json::object();
    for (const auto& [name, value] : e.parameters()) values[name] = value;
    if (effects.contains(e.name())) throw std::invalid_argument("array.parameters.effects: \"" + e.name() + "\" given twice");
    effects[e.name()] = values;
  }
  const ModelParams model = parse_model_params({{"surface", surface}, {"effects", effects}},
                                               SurfaceParameters::paper_defaults(out.geometry), "array.parameters");
  out.params = model.surface;
  out.params.validate();
  model.apply_to(out.simulator);
  return out;
}

ImportOptions import_options_from_proto(const v1::GoalOptions& options, const ServerLimits& limits) {
  ImportOptions out;
  out.hue = options.encoding() == v1::HEIGHT_ENCODING_HUE;
  out.max_pixels = limits.max_goal_pixels;
  // Empty: the importer's default, the mesh's sidecar "up_axis" if it has one, else z.
  if (std::string axis = options.up_axis(); !axis.empty()) {
    out.mesh_up_negative = axis[0] == '-';
    if (out.mesh_up_negative) axis.erase(0, 1);
    if (axis != "x" && axis != "y" && axis != "z")
      throw std::invalid_argument("goal.options.up_axis must be x, y, z, -x, -y or -z, got \"" + options.up_axis() + "\"");
    out.mesh_up_axis = axis[0];
  }
  if (options.view_resolution() < 0)
    throw std::invalid_argument("goal.options.view_resolution must be positive (0 = 256)");
  check_count("goal.options.view_resolution", options.view_resolution(), limits.max_view_resolution);
  if (options.view_resolution() > 0) out.mesh_resolution = options.view_resolution();
  out.validate();
  return out;
}

double max_height_from_proto(const v1::GoalOptions& options) {
  const double h = options.max_height_mm();
  if (h == 0.0) return 0.0;  // the array's default relief (default_relief_mm)
  if (!(h > 0.0) || !std::isfinite(h))
    throw std::invalid_argument("goal.options.max_height_mm must be positive and finite (0 = the array's default relief)");
  return h;
}

GoalHeights heights_from_proto(const v1::Goal& goal) {
  switch (goal.options().heights()) {
    case v1::GOAL_HEIGHTS_UNSPECIFIED:
    case v1::GOAL_HEIGHTS_SCALED: return GoalHeights::kScaled;
    case v1::GOAL_HEIGHTS_ABSOLUTE: break;
    default: throw std::invalid_argument("goal.options.heights: unknown value " + std::to_string(goal.options().heights()));
  }
  if (goal.options().max_height_mm() != 0.0)
    throw std::invalid_argument("goal.options.heights ABSOLUTE and goal.options.max_height_mm exclude each other");
  if (goal.has_file()) check_absolute_goal_format(goal.file().file_name());
  return GoalHeights::kAbsolute;
}

DeviceStep step_from_proto(const v1::Step& step, const std::string& where) {
  DeviceStep out;
  out.label = step.label();
  switch (step.op_case()) {
    case v1::Step::kSetPressure: out.action = Action::set_pressure(step.set_pressure().kpa() * 1000.0); break;
    case v1::Step::kJam: out.action = Action::jam(step.jam().row(), step.jam().col()); break;
    case v1::Step::kUnjam: out.action = Action::unjam(step.unjam().row(), step.unjam().col()); break;
    case v1::Step::kPin: out.action = Action::pin(step.pin().a(), step.pin().b()); break;
    case v1::Step::kUnpin: out.action = Action::unpin(step.unpin().a(), step.unpin().b()); break;
    case v1::Step::kCapture: out.capture = true; break;
    case v1::Step::OP_NOT_SET: throw std::invalid_argument(where + ": no op set");
  }
  return out;
}

void action_to_proto(const Action& action, v1::Step* out) {
  switch (action.op) {
    case Action::Op::kSetPressure: out->mutable_set_pressure()->set_kpa(action.pressure_pa / 1000.0); break;
    case Action::Op::kJam: out->mutable_jam()->set_row(action.a), out->mutable_jam()->set_col(action.b); break;
    case Action::Op::kUnjam: out->mutable_unjam()->set_row(action.a), out->mutable_unjam()->set_col(action.b); break;
    case Action::Op::kPin: out->mutable_pin()->set_a(action.a), out->mutable_pin()->set_b(action.b); break;
    case Action::Op::kUnpin: out->mutable_unpin()->set_a(action.a), out->mutable_unpin()->set_b(action.b); break;
  }
}

void snapshot_to_proto(const Mesh& mesh, const DeviceState& state, int steps_applied, v1::SurfaceSnapshot* out) {
  const Eigen::MatrixXd heights_mm = point_heights(mesh, state.x) * 1000.0;
  out->set_point_rows(int(heights_mm.rows()));
  out->set_point_cols(int(heights_mm.cols()));
  auto* h = out->mutable_heights_mm();
  h->Reserve(int(heights_mm.size()));
  for (int i = 0; i < heights_mm.rows(); ++i)
    for (int j = 0; j < heights_mm.cols(); ++j) h->Add(heights_mm(i, j));
  out->mutable_x_mm()->Reserve(int(heights_mm.size()));
  out->mutable_y_mm()->Reserve(int(heights_mm.size()));
  for (int i = 0; i < heights_mm.rows(); ++i)
    for (int j = 0; j < heights_mm.cols(); ++j) {
      out->add_x_mm(state.x(0, mesh.index(i, j)) * 1000.0);
      out->add_y_mm(state.x(1, mesh.index(i, j)) * 1000.0);
    }
  out->set_pressure_pa(state.pressure_pa);
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c)
      if (state.jammed(mesh, r, c)) {
        v1::CellIndex* cell = out->add_jammed_cells();
        cell->set_row(r), cell->set_col(c);
      }
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b)
      if (state.pinned(mesh, a, b)) {
        v1::NodeIndex* node = out->add_pinned_nodes();
        node->set_a(a), node->set_b(b);
      }
  out->set_steps_applied(steps_applied);
}

void capture_to_proto(const device::Capture& capture, v1::CaptureFrame* out) {
  v1::CaptureGrid* g = out->mutable_grid();
  g->set_nx(capture.grid.nx), g->set_ny(capture.grid.ny);
  g->set_x0_mm(capture.grid.x0_mm), g->set_y0_mm(capture.grid.y0_mm);
  g->set_dx_mm(capture.grid.dx_mm), g->set_dy_mm(capture.grid.dy_mm);
  auto* h = out->mutable_heights_mm();
  h->Reserve(int(capture.heights_mm.size()));
  for (int iy = 0; iy < capture.heights_mm.rows(); ++iy)
    for (int ix = 0; ix < capture.heights_mm.cols(); ++ix) h->Add(capture.heights_mm(iy, ix));
}

}  // namespace hj::server
