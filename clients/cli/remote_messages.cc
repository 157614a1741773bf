#include "remote_messages.h"

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hj::cli {

namespace v1 = ::hapticjam::v1;

namespace {

double number_at(const nlohmann::json& step, const char* key, const std::string& where) {
  if (!step.contains(key)) throw std::invalid_argument(where + ": missing key \"" + key + "\"");
  const auto& v = step.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw std::invalid_argument(where + ": key \"" + key + "\" needs a finite number");
  return v.get<double>();
}

std::pair<int, int> pair_at(const nlohmann::json& step, const char* key, const std::string& where) {
  if (!step.contains(key)) throw std::invalid_argument(where + ": missing key \"" + key + "\"");
  const auto& v = step.at(key);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() || !v[1].is_number_integer())
    throw std::invalid_argument(where + ": key \"" + key + "\" needs two whole numbers [i, j]");
  return {v[0].get<int>(), v[1].get<int>()};
}

}  // namespace

v1::Plan plan_from_steps_json(const nlohmann::json& doc, const std::string& source) {
  const nlohmann::json* steps = &doc;
  if (doc.is_object()) {
    if (!doc.contains("steps")) throw std::invalid_argument(source + ": missing key \"steps\"");
    steps = &doc.at("steps");
  }
  if (!steps->is_array()) throw std::invalid_argument(source + ": \"steps\" must be a list");
  v1::Plan plan;
  if (doc.is_object() && doc.contains("planner") && doc["planner"].is_string()) plan.set_planner(doc["planner"]);
  for (size_t i = 0; i < steps->size(); ++i) {
    const nlohmann::json& s = (*steps)[i];
    const std::string where = source + ": step " + std::to_string(i);
    if (!s.is_object() || !s.contains("op") || !s["op"].is_string())
      throw std::invalid_argument(where + ": missing key \"op\"");
    const std::string op = s["op"];
    v1::Step* step = plan.add_steps();
    if (s.contains("label") && s["label"].is_string()) step->set_label(s["label"]);
    if (op == "set_pressure") {
      step->mutable_set_pressure()->set_kpa(number_at(s, "kpa", where));
    } else if (op == "jam" || op == "unjam") {
      const auto [r, c] = pair_at(s, "cell", where);
      v1::CellIndex* cell = op == "jam" ? step->mutable_jam() : step->mutable_unjam();
      cell->set_row(r), cell->set_col(c);
    } else if (op == "pin" || op == "unpin") {
      const auto [a, b] = pair_at(s, "node", where);
      v1::NodeIndex* node = op == "pin" ? step->mutable_pin() : step->mutable_unpin();
      node->set_a(a), node->set_b(b);
    } else if (op == "capture") {
      step->mutable_capture();
    } else {
      throw std::invalid_argument(where + ": unknown op \"" + op + "\"");
    }
  }
  return plan;
}

Eigen::MatrixXd snapshot_heights(const v1::SurfaceSnapshot& snapshot) {
  const long n = long(snapshot.point_rows()) * snapshot.point_cols();
  if (snapshot.point_rows() < 1 || snapshot.point_cols() < 1 || n != snapshot.heights_mm_size())
    throw std::runtime_error("server sent a surface of " + std::to_string(snapshot.heights_mm_size()) +
                             " heights for " + std::to_string(snapshot.point_rows()) + " x " +
                             std::to_string(snapshot.point_cols()) + " points");
  Eigen::MatrixXd out(snapshot.point_rows(), snapshot.point_cols());
  for (int i = 0; i < out.rows(); ++i)
    for (int j = 0; j < out.cols(); ++j) out(i, j) = snapshot.heights_mm(i * out.cols() + j);
  return out;
}

Eigen::MatrixXd frame_heights(const v1::CaptureFrame& frame) {
  const auto& g = frame.grid();
  if (g.nx() < 1 || g.ny() < 1 || long(g.nx()) * g.ny() != frame.heights_mm_size())
    throw std::runtime_error("server sent a frame of " + std::to_string(frame.heights_mm_size()) + " heights for a " +
                             std::to_string(g.nx()) + " x " + std::to_string(g.ny()) + " grid");
  Eigen::MatrixXd out(g.ny(), g.nx());
  for (int iy = 0; iy < g.ny(); ++iy)
    for (int ix = 0; ix < g.nx(); ++ix) out(iy, ix) = frame.heights_mm(iy * g.nx() + ix);
  return out;
}

Eigen::MatrixXd goal_heights(const google::protobuf::RepeatedField<double>& heights_mm, Eigen::Index rows,
                             Eigen::Index cols) {
  if (heights_mm.size() != rows * cols)
    throw std::runtime_error("server sent a goal of " + std::to_string(heights_mm.size()) + " heights for " +
                             std::to_string(rows * cols) + " mesh points");
  Eigen::MatrixXd out(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j) out(i, j) = heights_mm[static_cast<int>(i * cols + j)];
  return out;
}

bool snapshot_positions(const v1::SurfaceSnapshot& snapshot, Eigen::MatrixXd& x_mm, Eigen::MatrixXd& y_mm) {
  const int n = snapshot.heights_mm_size();
  if (n == 0 || snapshot.x_mm_size() != n || snapshot.y_mm_size() != n) return false;
  x_mm.resize(snapshot.point_rows(), snapshot.point_cols());
  y_mm.resize(snapshot.point_rows(), snapshot.point_cols());
  for (int i = 0; i < x_mm.rows(); ++i)
    for (int j = 0; j < x_mm.cols(); ++j) {
      x_mm(i, j) = snapshot.x_mm(i * x_mm.cols() + j);
      y_mm(i, j) = snapshot.y_mm(i * x_mm.cols() + j);
    }
  return true;
}

SurfaceDifference compare_capture(const v1::CaptureFrame& frame, const Eigen::MatrixXd& predicted_mm,
                                  double point_spacing_mm, const Eigen::MatrixXd* x_mm, const Eigen::MatrixXd* y_mm) {
  const bool positioned = x_mm && y_mm && x_mm->rows() == predicted_mm.rows() && x_mm->cols() == predicted_mm.cols() &&
                          y_mm->rows() == predicted_mm.rows() && y_mm->cols() == predicted_mm.cols();
  const Eigen::MatrixXd z = frame_heights(frame);
  const auto& g = frame.grid();
  SurfaceDifference d;
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < predicted_mm.rows(); ++i)
    for (int j = 0; j < predicted_mm.cols(); ++j) {
      // Where mesh point (i, j) sits, in frame sample units:
      const double px = positioned ? (*x_mm)(i, j) : j * point_spacing_mm;
      const double py = positioned ? (*y_mm)(i, j) : i * point_spacing_mm;
      const double fx = (px - g.x0_mm()) / g.dx_mm();
      const double fy = (py - g.y0_mm()) / g.dy_mm();
      if (fx < 0 || fy < 0 || fx > g.nx() - 1 || fy > g.ny() - 1) continue;
      const int x0 = std::min(int(fx), std::max(g.nx() - 2, 0)), y0 = std::min(int(fy), std::max(g.ny() - 2, 0));
      const int x1 = std::min(x0 + 1, g.nx() - 1), y1 = std::min(y0 + 1, g.ny() - 1);
      const double tx = fx - x0, ty = fy - y0;
      const double captured = (1 - ty) * ((1 - tx) * z(y0, x0) + tx * z(y0, x1)) + ty * ((1 - tx) * z(y1, x0) + tx * z(y1, x1));
      if (!std::isfinite(captured)) continue;
      const double diff = captured - predicted_mm(i, j);
      ++d.points;
      sum += diff;
      sum_sq += diff * diff;
      d.max_abs_mm = std::max(d.max_abs_mm, std::abs(diff));
    }
  if (d.points > 0) {
    d.mean_mm = sum / d.points;
    d.rms_mm = std::sqrt(sum_sq / d.points);
  }
  return d;
}

std::string to_json_line(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string out;
  (void)google::protobuf::util::MessageToJsonString(message, &out, options);
  return out;
}

}  // namespace hj::cli
