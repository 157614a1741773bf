#include "model/device_state.h"

namespace hj {

DeviceState DeviceState::flat(const Mesh& mesh) {
  DeviceState s;
  s.x = mesh.rest_positions();
  s.cell_jammed.assign(mesh.num_cells(), 0);
  s.node_pinned.assign(mesh.num_nodes(), 0);
  s.phi_eq = Eigen::Matrix2Xd::Zero(2, mesh.num_points());
  return s;
}

std::vector<char> DeviceState::fixed_points(const Mesh& mesh) const {
  std::vector<char> fixed(mesh.num_points(), 0);
  for (int idx = 0; idx < mesh.num_points(); ++idx) fixed[idx] = mesh.is_boundary(idx);
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b)
      if (pinned(mesh, a, b)) fixed[mesh.node_point(a, b)] = 1;
  return fixed;
}

}  // namespace hj
