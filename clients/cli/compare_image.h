// The side-by-side picture of a plan: goal, predicted surface and their
// difference as colour maps on one scale, with the cell grid drawn.
#pragma once

#include <Eigen/Core>
#include <filesystem>

#include "model/mesh.h"

namespace hj::cli {

// goal_mm and predicted_mm are ((R p + 1) x (C p + 1)) mesh point heights.
void write_compare_png(const std::filesystem::path& path, const Mesh& mesh, const Eigen::MatrixXd& goal_mm,
                       const Eigen::MatrixXd& predicted_mm);

}  // namespace hj::cli
