// The least-squares plane (plane_fit.h) against planes known exactly: points on a tilted plane,
// the same with noise of both signs, and only the listed members counted.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "scenewatch/core/plane_fit.h"

namespace scenewatch {
namespace {

// Points on n . p + d = 0 over a grid around `centre`, each moved along n by offset(k).
template <typename Offset>
std::vector<Eigen::Vector3f> plane_points(const Eigen::Vector3d& n, const Eigen::Vector3d& centre, Offset offset) {
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector3f> out;
  for (int a = -5; a <= 5; ++a)
    for (int b = -5; b <= 5; ++b) {
      const double o = offset(static_cast<int>(out.size()));
      out.push_back((centre + 0.05 * a * u + 0.03 * b * v + o * n).cast<float>());
    }
  return out;
}

std::vector<int> all_of(const std::vector<Eigen::Vector3f>& points) {
  std::vector<int> ids(points.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
  return ids;
}

TEST(PlaneFit, FindsAnExactPlane) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.9, 0.4).normalized(), centre(0.3, 0.1, 1.2);
  const auto points = plane_points(n, centre, [](int) { return 0.0; });
  const PlaneFit fit = fit_plane_least_squares(points, all_of(points));
  EXPECT_NEAR(std::abs(fit.normal.dot(n)), 1.0, 1e-6);
  EXPECT_NEAR(fit.normal.norm(), 1.0, 1e-9);
  EXPECT_LT((fit.mean - centre).norm(), 1e-6);
  EXPECT_NEAR(std::abs(fit.normal.dot(fit.mean) - n.dot(centre)), 0.0, 1e-6);
}

TEST(PlaneFit, SymmetricNoiseLeavesThePlane) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitY(), centre(0, 0.8, 1.5);
  const auto points = plane_points(n, centre, [](int k) { return k % 2 == 0 ? 0.004 : -0.004; });
  const PlaneFit fit = fit_plane_least_squares(points, all_of(points));
  EXPECT_NEAR(std::abs(fit.normal.y()), 1.0, 1e-3);
  EXPECT_NEAR(fit.mean.y(), 0.8, 1e-3);
}

TEST(PlaneFit, UsesOnlyTheMembers) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ(), centre(0, 0, 2.0);
  auto points = plane_points(n, centre, [](int) { return 0.0; });
  std::vector<int> members = all_of(points);
  points.push_back(Eigen::Vector3f(0.0f, 0.0f, 5.0f));  // far off the plane, not a member
  const PlaneFit fit = fit_plane_least_squares(points, members);
  EXPECT_NEAR(std::abs(fit.normal.z()), 1.0, 1e-6);
  EXPECT_NEAR(fit.mean.z(), 2.0, 1e-6);
}

}  // namespace
}  // namespace scenewatch
