// Synthetic meshes for the top-view and mesh-import tests: boxes, a
// hemisphere, an overhang, an ASCII STL writer, and NaN-aware comparisons.
#pragma once

#include <gtest/gtest.h>

#include "expect_error.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <string>
#include <vector>

#include "shapes/top_view.h"

namespace hj::testing_support {

using V = Eigen::Vector3d;

// The 12 outward-wound triangles of the axis-aligned box [lo, hi].
inline std::vector<Triangle3d> box(const V& lo, const V& hi) {
  const auto p = [&](int i) { return V(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()); };
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle3d> out;
  for (const auto& q : quads) {
    out.push_back({p(q[0]), p(q[1]), p(q[2])});
    out.push_back({p(q[0]), p(q[2]), p(q[3])});
  }
  return out;
}

// Upper half of the unit sphere, (rings x segments) quads in polar angle and
// azimuth, the pole fan as triangles: 16 x 64 gives 1984 triangles.
inline std::vector<Triangle3d> hemisphere(int rings, int segments) {
  const auto p = [&](int ring, int seg) {
    const double theta = M_PI / 2 * ring / rings, phi = 2 * M_PI * seg / segments;
    return V(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  std::vector<Triangle3d> out;
  for (int s = 0; s < segments; ++s) {
    out.push_back({p(0, 0), p(1, s), p(1, s + 1)});
    for (int r = 1; r < rings; ++r) {
      out.push_back({p(r, s), p(r + 1, s), p(r + 1, s + 1)});
      out.push_back({p(r, s), p(r + 1, s + 1), p(r, s + 1)});
    }
  }
  return out;
}

// A lower box [0,4]x[0,2]x[0,1] and a box [2,6]x[0.5,1.8]x[2,3] floating above
// it, half over it (asymmetric in x and y, so a mirrored import shows).
inline std::vector<Triangle3d> overhang() {
  auto tris = box(V(0, 0, 0), V(4, 2, 1));
  for (const auto& t : box(V(2, 0.5, 2), V(6, 1.8, 3))) tris.push_back(t);
  return tris;
}

inline void write_ascii_stl(const std::filesystem::path& file, const std::vector<Triangle3d>& tris,
                     const std::function<V(const V&)>& map = [](const V& v) { return v; }) {
  std::ofstream out(file);
  out << std::setprecision(17) << "solid test\n";
  for (const auto& t : tris) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (const auto& v : t) {
      const V w = map(v);
      out << "   vertex " << w.x() << " " << w.y() << " " << w.z() << "\n";
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid test\n";
}


constexpr double kInf = std::numeric_limits<double>::infinity();
inline double nan_max(const Eigen::MatrixXd& z) { return z.array().isNaN().select(-kInf, z.array()).maxCoeff(); }
inline double nan_min(const Eigen::MatrixXd& z) { return z.array().isNaN().select(kInf, z.array()).minCoeff(); }

}  // namespace hj::testing_support
