// Mesh goals (seed paper, section 5.3) through import_goal: a hemisphere,
// an overhang, up-axis rotations, the real meshes in shared/data/mesh, and
// errors naming the file or option.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "matrix_checks.h"
#include "mesh_fixtures.h"
#include "shapes/resample.h"
#include <limits>
#include "scratch_dir.h"
#include "shapes/goal_importer.h"
#include "shapes/mesh_importer.h"
#include "shapes/top_view.h"

namespace hj {
namespace {

using namespace testing_support;
using V = Eigen::Vector3d;
const std::filesystem::path kMeshDir = std::filesystem::path(HJ_SHARED_DIR) / "data" / "mesh";

TEST(MeshImport, HemisphereIsSqrtOneMinusRSquared) {
  const ScratchDir dir("hemi");
  const auto tris = hemisphere(16, 64);
  ASSERT_EQ(tris.size(), 1984u);
  write_ascii_stl(dir.path / "hemi.stl", tris);
  ImportOptions options;
  options.mesh_resolution = 101;
  const HeightMap map = import_goal(dir.path / "hemi.stl", options);
  const TopView raw = render_top_view(load_mesh_triangles(dir.path / "hemi.stl", options), 101);
  ASSERT_EQ(map.z.rows(), 101);
  ASSERT_EQ(map.z.cols(), 101);
  expect_same(map.z, raw.z.array() - nan_min(raw.z), 1e-12);
  double worst = 0.0;
  for (Eigen::Index r = 0; r < raw.z.rows(); ++r)
    for (Eigen::Index c = 0; c < raw.z.cols(); ++c) {
      const double x = raw.x_min + (c + 0.5) * raw.pixel_size, y = raw.y_max - (r + 0.5) * raw.pixel_size;
      const double rho = std::hypot(x, y);
      if (rho > 1.0) {
        EXPECT_TRUE(std::isnan(raw.z(r, c))) << r << "," << c;
      }
      // The facets stand inside the sphere; only a thin rim band (the last
      // ring and chords) departs from the sphere by more than 0.02.
      if (rho <= 0.99) {
        ASSERT_FALSE(std::isnan(raw.z(r, c))) << r << "," << c;
        worst = std::max(worst, std::abs(raw.z(r, c) - std::sqrt(1 - rho * rho)));
      }
    }
  EXPECT_LT(worst, 0.02);
  EXPECT_NEAR(nan_max(map.z) + nan_min(raw.z), 1.0, 0.002);
}

TEST(MeshImport, OverhangShowsTheHigherSurface) {
  const ScratchDir dir("overhang");
  write_ascii_stl(dir.path / "o.stl", overhang());
  ImportOptions options;
  options.mesh_resolution = 60;  // 0.1 per pixel over x in [0, 6]
  const HeightMap map = import_goal(dir.path / "o.stl", options);
  ASSERT_EQ(map.z.cols(), 60);
  ASSERT_EQ(map.z.rows(), 20);
  // Pixel (row, col) centre: x = 0.05 + 0.1 col, y = 1.95 - 0.1 row.
  EXPECT_NEAR(map.z(10, 10), 0.0, 1e-9);   // lower box only: the lowest visible surface
  EXPECT_NEAR(map.z(10, 30), 2.0, 1e-9);   // overlap: upper box on top
  EXPECT_NEAR(map.z(10, 50), 2.0, 1e-9);   // upper box alone
  EXPECT_NEAR(map.z(1, 30), 0.0, 1e-9);    // overlap columns, north of the upper box
  EXPECT_TRUE(std::isnan(map.z(1, 50)));   // nothing there
  EXPECT_TRUE(std::isnan(map.z(18, 50)));
}

TEST(MeshImport, UpAxisRotationsImportIdentically) {
  const ScratchDir dir("up");
  write_ascii_stl(dir.path / "z.stl", overhang());
  const HeightMap reference = import_goal(dir.path / "z.stl");
  // Inverse of each rotation to +z, applied when writing the file.
  const struct {
    char axis;
    bool negative;
    std::function<V(const V&)> from_z_up;
  } cases[] = {
      {'y', false, [](const V& v) { return V(v.x(), v.z(), -v.y()); }},
      {'y', true, [](const V& v) { return V(v.x(), -v.z(), v.y()); }},
      {'x', false, [](const V& v) { return V(v.z(), v.x(), v.y()); }},
      {'x', true, [](const V& v) { return V(-v.z(), v.x(), -v.y()); }},
      {'z', true, [](const V& v) { return V(v.x(), -v.y(), -v.z()); }},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::string(c.negative ? "-" : "+") + c.axis);
    const auto file = dir.path / (std::string(1, c.axis) + (c.negative ? "neg" : "pos") + ".stl");
    write_ascii_stl(file, overhang(), c.from_z_up);
    ImportOptions options;
    options.mesh_up_axis = c.axis;
    options.mesh_up_negative = c.negative;
    expect_same(import_goal(file, options).z, reference.z, 1e-12);
  }
}

// "up_axis": "+Y ..." and the bbox, from a mesh's JSON.
struct MeshFacts {
  int up = 2;
  bool negative = false;
  double bbox_min[3] = {}, bbox_max[3] = {};
};

MeshFacts read_facts(const std::filesystem::path& json) {
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  MeshFacts f;
  const auto at = [&](const std::string& key) { return text.find(":", text.find("\"" + key + "\"")) + 1; };
  const std::string up = text.substr(text.find('"', at("up_axis")) + 1, 2);
  f.negative = up[0] == '-';
  f.up = std::tolower(up[1]) - 'x';
  for (const auto& [key, out] : {std::pair{"bbox_min", f.bbox_min}, std::pair{"bbox_max", f.bbox_max}}) {
    std::istringstream nums(text.substr(text.find('[', at(key)) + 1));
    char comma;
    nums >> out[0] >> comma >> out[1] >> comma >> out[2];
  }
  return f;
}

TEST(MeshImport, TheSidecarsUpAxisIsTheDefault) {
  // plan, sweep and the server import a shared mesh the same way: its
  // NAME.json says which way is up unless the caller says otherwise.
  const std::filesystem::path bunny = kMeshDir / "stanford_bunny.stl";
  const MeshFacts facts = read_facts(kMeshDir / "stanford_bunny.json");
  ImportOptions stated;
  stated.mesh_up_axis = char('x' + facts.up);
  stated.mesh_up_negative = facts.negative;
  ASSERT_NE(stated.mesh_up_axis, 'z');
  // Top views hold NaN where nothing is seen: equal means the same NaNs and values.
  const auto same_view = [](const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && (a.array().isNaN() == b.array().isNaN()).all() &&
           (a.array().isNaN()).select(0.0, a.array() - b.array()).abs().maxCoeff() == 0.0;
  };
  EXPECT_TRUE(same_view(import_goal(bunny).z, import_goal(bunny, stated).z));
  ImportOptions no_sidecar, z_up;
  no_sidecar.sidecar = false;
  z_up.mesh_up_axis = 'z';
  EXPECT_TRUE(same_view(import_goal(bunny, no_sidecar).z, import_goal(bunny, z_up).z));
  EXPECT_FALSE(same_view(import_goal(bunny, no_sidecar).z, import_goal(bunny).z));
}

TEST(MeshImport, ASidecarWithABadUpAxisIsNamed) {
  const ScratchDir dir("bad-up");
  write_ascii_stl(dir.path / "box.stl", box(V(0, 0, 0), V(1, 1, 1)));
  std::ofstream(dir.path / "box.json") << R"({"up_axis": "+W"})";
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "box.stl"); }, {"box.json", "+W", "up_axis"});
  ImportOptions stated;
  stated.mesh_up_axis = 'z';  // an up axis the caller states is not read from the sidecar
  EXPECT_NO_THROW((void)import_goal(dir.path / "box.stl", stated));
  std::ofstream(dir.path / "box.json", std::ios::trunc) << "{not json";
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "box.stl"); }, {"box.json", "not valid JSON"});
}

TEST(MeshImport, RealMeshesFromSharedData) {
  const std::vector<std::pair<std::string, std::string>> meshes = {
      {"stanford_bunny.stl", "stanford_bunny"}, {"stanford_bunny.obj", "stanford_bunny"},
      {"cgal_fandisk.stl", "cgal_fandisk"},     {"cgal_femur.stl", "cgal_femur"},
      {"utah_teapot.stl", "utah_teapot"},       {"openscad_letterblock.stl", "openscad_letterblock"}};
  for (const auto& [file, name] : meshes) {
    SCOPED_TRACE(file);
    const MeshFacts facts = read_facts(kMeshDir / (name + ".json"));
    ImportOptions options;
    options.mesh_up_axis = char('x' + facts.up);
    options.mesh_up_negative = facts.negative;
    const auto start = std::chrono::steady_clock::now();
    const HeightMap map = import_goal(kMeshDir / file, options);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const TopView raw = render_top_view(load_mesh_triangles(kMeshDir / file, options), options.mesh_resolution);

    const double top = facts.negative ? -facts.bbox_min[facts.up] : facts.bbox_max[facts.up];
    const double bottom = facts.negative ? -facts.bbox_max[facts.up] : facts.bbox_min[facts.up];
    const double extent = top - bottom;
    EXPECT_EQ(std::max(map.z.rows(), map.z.cols()), 256);
    EXPECT_GT((!map.z.array().isNaN()).count(), map.z.size() / 4);
    EXPECT_NEAR(nan_min(map.z), 0.0, 0.0);
    // The highest point is always seen from above; the lowest visible
    // surface is not the bottom of the bbox unless the base shows at the rim.
    EXPECT_NEAR(nan_max(raw.z), top, 0.01 * extent);
    EXPECT_NEAR(nan_max(map.z), nan_max(raw.z) - nan_min(raw.z), 1e-9 * extent);
    EXPECT_LE(nan_max(map.z), extent * 1.01);
    std::printf("[ mesh ] %-26s %4ld x %4ld, %6.1f ms, max %.4g of bbox extent %.4g along up (%.0f %%)\n",
                file.c_str(), long(map.z.rows()), long(map.z.cols()), ms, nan_max(map.z), extent,
                100 * nan_max(map.z) / extent);
  }
}

TEST(MeshImport, ErrorsNameTheFileOrField) {
  const ScratchDir dir("errors");
  std::mt19937 rng(7);
  {
    std::ofstream out(dir.path / "noise.stl", std::ios::binary);
    for (int k = 0; k < 1000; ++k) out.put(char(rng() & 0xff));
  }
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "noise.stl"); }, {"noise.stl"});
  std::ofstream(dir.path / "empty.obj").close();
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "empty.obj"); }, {"empty.obj", "empty"});
  std::ofstream(dir.path / "comments.obj") << "# nothing here\n";
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "comments.obj"); }, {"comments.obj"});
  std::ofstream(dir.path / "points.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n";
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "points.obj"); }, {"points.obj"});
  write_ascii_stl(dir.path / "wall.stl", {{V(0, 0, 0), V(1, 0, 0), V(0, 0, 1)}});
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "wall.stl"); }, {"wall.stl", "mesh_up_axis"});

  write_ascii_stl(dir.path / "box.stl", box(V(0, 0, 0), V(1, 1, 1)));
  ImportOptions zero;
  zero.mesh_resolution = 0;
  expect_error<std::invalid_argument>([&] { (void)import_goal(dir.path / "box.stl", zero); }, {"mesh_resolution"});
  ImportOptions big;
  big.max_pixels = 1000;
  expect_error<ImportError>([&] { (void)import_goal(dir.path / "box.stl", big); },
                            {"box.stl", "mesh_resolution", "max_pixels"});
  ImportOptions w;
  w.mesh_up_axis = 'w';
  expect_error<std::invalid_argument>([&] { (void)import_goal(dir.path / "box.stl", w); }, {"mesh_up_axis", "'w'"});
}

}  // namespace
}  // namespace hj

namespace hj {
namespace {

TEST(MeshImport, TheFloorAroundAPartResamplesToZero) {
  // A mesh's uncovered pixels are the floor (height 0), not missing data.
  HeightMap part;
  part.z = Eigen::MatrixXd::Constant(40, 40, std::numeric_limits<double>::quiet_NaN());
  part.z.block(15, 15, 10, 10).setConstant(5.0);
  part.uncovered_height = 0.0;
  const Mesh mesh(ArrayGeometry{3, 3, 0.038, 4});
  const Eigen::MatrixXd fitted = resample_to_mesh(part, mesh, 30.0);
  EXPECT_DOUBLE_EQ(fitted(0, 0), 0.0);                                      // a corner: floor
  EXPECT_DOUBLE_EQ(fitted(mesh.point_rows() / 2, mesh.point_cols() / 2), 30.0);  // the part's top
  part.uncovered_height.reset();  // as missing data: the nearest valid value
  EXPECT_DOUBLE_EQ(resample_to_mesh(part, mesh, 30.0).minCoeff(), 0.0);
}

}  // namespace
}  // namespace hj
