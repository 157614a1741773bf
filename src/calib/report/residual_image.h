// The residual heat map of one capture (predicted - measured, mm) on the
// session's sample grid as a PNG: a fixed diverging scale (blue below, red
// above, white at zero) with a legend, +y up, cell borders and nodes drawn
// (pinned nodes filled), samples not compared in grey.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "calib/session.h"

namespace hj {

// The PNG file's bytes.
// @param residual_mm  (ny x nx), NaN where not compared
// @param scale_mm     the colour scale spans [-scale_mm, +scale_mm]
std::string residual_png(const Session& session, const Eigen::MatrixXd& residual_mm, double scale_mm,
                         const std::vector<std::pair<int, int>>& pinned, const std::string& title);

// The same written to `path` (folders made as needed); std::runtime_error
// naming the file if it cannot be written.
void write_residual_png(const std::filesystem::path& path, const Session& session, const Eigen::MatrixXd& residual_mm,
                        double scale_mm, const std::vector<std::pair<int, int>>& pinned, const std::string& title);

}  // namespace hj
