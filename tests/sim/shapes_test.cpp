// Ray intersection against the signed distance (an independent description of each surface).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scenewatch/sim/shapes.h"

namespace scenewatch::sim {
namespace {

std::vector<Shape> all_shapes() {
  std::vector<Shape> v;
  Shape box;
  box.kind = ShapeKind::kBox;
  box.size_m = {0.2, 0.1, 0.3};
  v.push_back(box);
  Shape cyl;
  cyl.kind = ShapeKind::kCylinder;
  cyl.radius_m = 0.04;
  cyl.height_m = 0.1;
  v.push_back(cyl);
  Shape cup = cyl;
  cup.open_top = true;
  cup.wall_m = 0.005;
  v.push_back(cup);
  Shape cone;
  cone.kind = ShapeKind::kFrustum;
  cone.radius_m = 0.06;
  cone.top_radius_m = 0.0;
  cone.height_m = 0.12;
  v.push_back(cone);
  Shape glass;
  glass.kind = ShapeKind::kFrustum;
  glass.radius_m = 0.03;
  glass.top_radius_m = 0.037;
  glass.height_m = 0.13;
  glass.open_top = true;
  glass.wall_m = 0.003;
  v.push_back(glass);
  Shape bowl = glass;
  bowl.radius_m = 0.045;
  bowl.top_radius_m = 0.08;
  bowl.height_m = 0.065;
  v.push_back(bowl);
  Shape sphere;
  sphere.kind = ShapeKind::kSphere;
  sphere.radius_m = 0.05;
  v.push_back(sphere);
  Shape capsule;
  capsule.kind = ShapeKind::kCapsule;
  capsule.radius_m = 0.03;
  capsule.height_m = 0.2;
  v.push_back(capsule);
  return v;
}

TEST(Shapes, HitsLieOnTheSurfaceAndAreTheFirstCrossing) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const Shape& s : all_shapes()) {
    Eigen::Vector3d c;
    double r = 0;
    bounding_sphere(s, &c, &r);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
      // Rays from outside the bounding sphere towards a random point inside it; unnormalised dirs.
      Eigen::Vector3d o(u(rng), u(rng), u(rng));
      o = c + o.normalized() * (r * 2.5);
      const Eigen::Vector3d target = c + r * Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.8;
      const Eigen::Vector3d d = (target - o) * (0.5 + std::abs(u(rng)));
      ShapeHit hit;
      if (!intersect(s, o, d, 1e-9, 1e9, &hit)) {
        // A miss: no point along the ray is inside.
        for (int k = 0; k <= 200; ++k) {
          ASSERT_GT(signed_distance(s, o + d * (k / 100.0)), -1e-9) << to_string(s.kind);
        }
        continue;
      }
      ++hits;
      const Eigen::Vector3d p = o + hit.t * d;
      EXPECT_NEAR(signed_distance(s, p), 0.0, 1e-9) << to_string(s.kind);
      EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-9);
      // Outward normal: a step along it leaves the solid.
      EXPECT_GT(signed_distance(s, p + 1e-4 * hit.normal), 0.0) << to_string(s.kind);
      // Nothing before the hit is inside the solid.
      for (int k = 0; k < 50; ++k) {
        ASSERT_GT(signed_distance(s, o + d * (hit.t * k / 50.0)), -1e-9) << to_string(s.kind);
      }
      // The surface lies inside the bounding sphere.
      EXPECT_LE((p - c).norm(), r + 1e-9);
    }
    EXPECT_GT(hits, 500) << to_string(s.kind);
  }
}

TEST(Shapes, OpenCupShowsItsInsideFromAbove) {
  Shape cup;
  cup.kind = ShapeKind::kCylinder;
  cup.radius_m = 0.04;
  cup.height_m = 0.1;
  cup.open_top = true;
  cup.wall_m = 0.005;
  ShapeHit hit;
  // Straight down the middle: the inner bottom at z = wall.
  ASSERT_TRUE(intersect(cup, {0, 0, 1}, {0, 0, -1}, 0, 10, &hit));
  EXPECT_NEAR(1.0 - hit.t, cup.wall_m, 1e-12);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
  // Onto the rim.
  ASSERT_TRUE(intersect(cup, {0.0375, 0, 1}, {0, 0, -1}, 0, 10, &hit));
  EXPECT_NEAR(1.0 - hit.t, 0.1, 1e-12);
  // A closed cylinder is hit on its top.
  cup.open_top = false;
  ASSERT_TRUE(intersect(cup, {0, 0, 1}, {0, 0, -1}, 0, 10, &hit));
  EXPECT_NEAR(1.0 - hit.t, 0.1, 1e-12);
}

TEST(Shapes, RespectsTheRayInterval) {
  Shape box;
  box.kind = ShapeKind::kBox;
  box.size_m = {1, 1, 1};
  ShapeHit hit;
  ASSERT_TRUE(intersect(box, {0, 0, 3}, {0, 0, -1}, 0, 10, &hit));
  EXPECT_NEAR(hit.t, 2.0, 1e-12);
  EXPECT_FALSE(intersect(box, {0, 0, 3}, {0, 0, -1}, 0, 1.5, &hit));
  // Starting inside: the exit.
  ASSERT_TRUE(intersect(box, {0, 0, 0.5}, {0, 0, 1}, 0, 10, &hit));
  EXPECT_NEAR(hit.t, 0.5, 1e-12);
}

}  // namespace
}  // namespace scenewatch::sim
