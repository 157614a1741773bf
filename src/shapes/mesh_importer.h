// Goal import from a 3-D mesh (STL, OBJ, PLY, glTF, 3MF via Assimp): the top
// view as a height image (seed paper, section 5.3; top_view.h), the lowest
// visible surface at 0. The importer registers itself for import_goal().
#pragma once

#include <filesystem>
#include <vector>

#include "shapes/goal_importer.h"
#include "shapes/top_view.h"

namespace hj {

// Meshes with more triangles are refused (memory and time guard: about 72
// bytes per triangle copied, on top of what Assimp itself holds while it
// reads the file, which happens before this count is known).
constexpr long kMaxMeshTriangles = 5'000'000;

// The file's triangles, node transforms applied, rotated (right-handed) so
// the up axis of `options` (mesh_up_axis, mesh_up_negative) becomes +z.
// @throws ImportError naming the file if Assimp cannot read it, it holds no
//         triangles or more than kMaxMeshTriangles, or a non-finite coordinate.
std::vector<Triangle3d> load_mesh_triangles(const std::filesystem::path& file, const ImportOptions& options);

}  // namespace hj
