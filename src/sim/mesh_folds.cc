#include "sim/mesh_folds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hj {

std::string MeshFolds::describe() const {
  if (count == 0) return "";
  char text[160];
  std::snprintf(text, sizeof text, "the mesh is folded at %d place%s, sharpest %.0f degrees at point (%d, %d) along %c",
                count, count == 1 ? "" : "s", sharpest_deg, row, col, axis);
  return text;
}

MeshFolds find_mesh_folds(const Mesh& mesh, const Eigen::Matrix3Xd& x) {
  MeshFolds folds;
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j)
      for (char axis : {'x', 'y'}) {
        const bool along_x = axis == 'x';
        if (along_x ? (j == 0 || j + 1 == mesh.point_cols()) : (i == 0 || i + 1 == mesh.point_rows())) continue;
        const int a = along_x ? mesh.index(i, j - 1) : mesh.index(i - 1, j);
        const int b = along_x ? mesh.index(i, j + 1) : mesh.index(i + 1, j);
        const Eigen::Vector3d e1 = x.col(mesh.index(i, j)) - x.col(a), e2 = x.col(b) - x.col(mesh.index(i, j));
        const double norms = e1.norm() * e2.norm();
        if (!(norms > 0.0)) continue;
        const double bend_deg = std::acos(std::clamp(e1.dot(e2) / norms, -1.0, 1.0)) * 180.0 / M_PI;
        if (bend_deg <= 90.0) continue;
        ++folds.count;
        if (bend_deg > folds.sharpest_deg) folds = {folds.count, bend_deg, i, j, axis};
      }
  return folds;
}

}  // namespace hj
