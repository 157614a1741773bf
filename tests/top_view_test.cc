// The z-buffer top view (seed paper, section 5.3) on boxes: top face
// everywhere, row 0 north, square pixels, bad input refused.
#include <gtest/gtest.h>

#include <stdexcept>

#include "mesh_fixtures.h"
#include "shapes/top_view.h"

namespace hj {
namespace {

using testing_support::box;
using V = Eigen::Vector3d;

TEST(TopView, UnitBoxShowsItsTopFaceEverywhere) {
  const TopView view = render_top_view(box(V(0, 0, 0), V(1, 1, 1)), 20);
  ASSERT_EQ(view.z.rows(), 20);
  ASSERT_EQ(view.z.cols(), 20);
  EXPECT_DOUBLE_EQ(view.pixel_size, 0.05);
  for (Eigen::Index k = 0; k < view.z.size(); ++k) EXPECT_NEAR(view.z.data()[k], 1.0, 1e-12) << k;
}

TEST(TopView, RowZeroIsNorthAndPixelsAreSquare) {
  // A 2 x 1 box, sloped so that z grows with y: north rows are higher.
  auto tris = box(V(0, 0, 0), V(2, 1, 1));
  for (auto& t : tris)
    for (auto& v : t) v.z() += v.y();
  const TopView view = render_top_view(tris, 8);
  ASSERT_EQ(view.z.cols(), 8);
  ASSERT_EQ(view.z.rows(), 4);
  EXPECT_GT(view.z(0, 3), view.z(3, 3));
  EXPECT_NEAR(view.z(0, 0), 1.0 + (1.0 - 0.125), 1e-12);  // pixel centre y = 0.875
}

TEST(TopView, RejectsBadInput) {
  EXPECT_THROW(render_top_view(box(V(0, 0, 0), V(1, 1, 1)), 0), std::invalid_argument);
  EXPECT_THROW(render_top_view({}, 8), std::invalid_argument);
  EXPECT_THROW(render_top_view({{V(0, 0, 0), V(0, 0, 1), V(0, 0, 2)}}, 8), std::invalid_argument);
}

}  // namespace
}  // namespace hj
