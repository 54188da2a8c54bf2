// Completion: the fitted primitive's whole surface.
#include <gtest/gtest.h>

#include <algorithm>

#include "scenewatch/ontology/completion.h"

namespace scenewatch::ontology {
namespace {

// The completed surface lies on the primitive, covers it evenly, and stays bounded for huge objects.
TEST(CompletionTest, PointsOnTheSurfaceAndBounded) {
  ShapeFit can;
  can.shape = ClassShape::kCylinder;
  can.center = Eigen::Vector3d(0.1, 0.2, 0.81);
  can.radius_m = can.bottom_radius_m = can.top_radius_m = 0.033;
  can.height_m = 0.12;
  const auto points = complete_surface(can, 0.004, false);
  double worst = 0, top = 0;
  for (const auto& p : points) worst = std::max(worst, surface_distance(can, p)), top = std::max(top, p.z());
  EXPECT_LT(worst, 1e-9);
  EXPECT_NEAR(top, 0.87, 1e-9);
  // Area 2 pi r h + 2 pi r^2 = 0.0317 m2 at 4 mm spacing: about 2000 points.
  EXPECT_GT(points.size(), 1500u);
  EXPECT_LT(points.size(), 3000u);
  const auto open = complete_surface(can, 0.004, true);
  EXPECT_LT(open.size(), points.size());
  ShapeFit box;
  box.shape = ClassShape::kBox;
  box.size_m = Eigen::Vector2d(2.0, 2.0);
  box.height_m = 2.0;
  EXPECT_LT(complete_surface(box, 0.001, false).size(), 2 * kMaxCompletedPoints);
}

}  // namespace
}  // namespace scenewatch::ontology
