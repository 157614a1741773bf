#include "calib/residual_pattern.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>

namespace hj {

namespace {

struct Accumulator {
  double sum_sq = 0.0;
  long n = 0;
  void add(double r) {
    sum_sq += r * r;
    ++n;
  }
  double rmse() const { return n ? std::sqrt(sum_sq / n) : std::nan(""); }
};

// Whether a sample is "in" the region; called for every compared sample.
using Region = std::function<bool(const MeasuredSession&, const MeasuredCapture&, int ix, int iy)>;

ResidualSplit split(const Dataset& dataset, const Evaluation& evaluation, const std::string& name,
                    const std::string& other, const Region& region) {
  Accumulator in, out;
  for (size_t s = 0; s < dataset.sessions.size(); ++s)
    for (size_t c = 0; c < dataset.sessions[s].captures.size(); ++c) {
      const Eigen::MatrixXd& res = evaluation.sessions[s].captures[c].residual_mm;
      for (int iy = 0; iy < res.rows(); ++iy)
        for (int ix = 0; ix < res.cols(); ++ix) {
          if (std::isnan(res(iy, ix))) continue;
          (region(dataset.sessions[s], dataset.sessions[s].captures[c], ix, iy) ? in : out).add(res(iy, ix));
        }
    }
  return {name, other, in.rmse(), out.rmse(), in.n, out.n};
}

}  // namespace

ResidualPattern describe_residuals(const Dataset& dataset, const Evaluation& evaluation, int worst) {
  ResidualPattern out;
  const Eigen::MatrixXd cells = evaluation.cell_rmse_mm();
  std::vector<std::pair<int, int>> order;
  for (int r = 0; r < cells.rows(); ++r)
    for (int c = 0; c < cells.cols(); ++c)
      if (!std::isnan(cells(r, c))) order.push_back({r, c});
  std::sort(order.begin(), order.end(),
            [&](auto a, auto b) { return cells(a.first, a.second) > cells(b.first, b.second); });
  order.resize(std::min<size_t>(order.size(), worst));
  out.worst_cells = order;
  for (auto [r, c] : order) out.worst_cell_rmse_mm.push_back(cells(r, c));

  // The median capture pressure separates high from low.
  std::vector<double> pressures;
  for (const auto& s : dataset.sessions)
    for (const auto& c : s.captures) pressures.push_back(c.pressure_pa);
  std::nth_element(pressures.begin(), pressures.begin() + pressures.size() / 2, pressures.end());
  const double median_pa = pressures.empty() ? 0.0 : pressures[pressures.size() / 2];

  auto near_pin = [](const MeasuredSession& ms, const MeasuredCapture& cap, int ix, int iy) {
    const double s = ms.session.device.cell_size_mm;
    for (auto [a, b] : cap.pinned)
      if (std::hypot(ms.session.grid.x_mm(ix) - b * s, ms.session.grid.y_mm(iy) - a * s) <= s / 4.0) return true;
    return false;
  };
  auto near_edge = [](const MeasuredSession& ms, const MeasuredCapture&, int ix, int iy) {
    const double s = ms.session.device.cell_size_mm;
    const double x = ms.session.grid.x_mm(ix), y = ms.session.grid.y_mm(iy);
    const double d = std::min({x, y, ms.session.device.cols * s - x, ms.session.device.rows * s - y});
    return d <= s / 4.0;
  };
  auto in_jammed = [](const MeasuredSession& ms, const MeasuredCapture& cap, int ix, int iy) {
    int r = 0, c = 0;
    return cell_of_sample(ms.session, ix, iy, r, c) && cap.jammed[r * ms.session.device.cols + c];
  };
  auto high_pressure = [median_pa](const MeasuredSession&, const MeasuredCapture& cap, int, int) {
    return cap.pressure_pa > median_pa;
  };
  char above[64];
  std::snprintf(above, sizeof above, "above %.2f kPa", median_pa / 1000.0);
  out.splits = {split(dataset, evaluation, "near pinned nodes", "elsewhere", near_pin),
                split(dataset, evaluation, "near the clamped edge", "inside", near_edge),
                split(dataset, evaluation, "in jammed cells", "in unjammed cells", in_jammed),
                split(dataset, evaluation, std::string("at high pressure (") + above + ")", "at low pressure",
                      high_pressure)};

  char line[256];
  if (!out.worst_cells.empty()) {
    std::string cells_text;
    for (size_t k = 0; k < out.worst_cells.size(); ++k) {
      std::snprintf(line, sizeof line, "%s[%d, %d] (%.2f mm)", k ? ", " : "", out.worst_cells[k].first,
                    out.worst_cells[k].second, out.worst_cell_rmse_mm[k]);
      cells_text += line;
    }
    std::snprintf(line, sizeof line, "The residual is largest in cells %s; over all cells the RMSE is %.2f mm.",
                  cells_text.c_str(), evaluation.rmse_mm());
    out.findings.push_back(line);
  }
  for (const auto& s : out.splits) {
    if (s.samples == 0 || s.other_samples == 0) continue;
    const double ratio = s.rmse_mm / s.other_rmse_mm;
    if (ratio >= 1.25 || ratio <= 0.8) {
      std::snprintf(line, sizeof line, "It is %s %s (%.2f mm) than %s (%.2f mm).", ratio >= 1.25 ? "larger" : "smaller",
                    s.name.c_str(), s.rmse_mm, s.other.c_str(), s.other_rmse_mm);
      out.findings.push_back(line);
    }
  }
  if (out.findings.size() <= 1)
    out.findings.push_back("It is spread evenly: no region (pins, edge, jammed cells, pressure) stands out.");
  return out;
}

}  // namespace hj
