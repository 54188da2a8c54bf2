// fit_object on bad input: clear errors, no crash. And the shape detection on exact shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "scenewatch/ontology/fit.h"

namespace scenewatch::ontology {
namespace {

Cloud sphere_cloud(const Eigen::Vector3d& center, double radius, int n) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  Cloud cloud;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d d(g(rng), g(rng), g(rng));
    d.normalize();
    if (d.z() > 0) d.z() = -d.z();  // the half facing a camera at the origin
    PointT p;
    p.getVector3fMap() = (center + radius * d).cast<float>();
    cloud.push_back(p);
  }
  return cloud;
}

std::vector<int> all(const Cloud& cloud) {
  std::vector<int> indices(cloud.size());
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
  return indices;
}

TEST(FitTest, TooFewPointsIsAnErrorThatSaysHowMany) {
  const Cloud cloud = sphere_cloud(Eigen::Vector3d(0, 0, 1), 0.05, 30);
  const auto fit = fit_object(cloud, all(cloud));
  ASSERT_FALSE(fit.ok());
  EXPECT_EQ(fit.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(fit.error().message.find("30 valid points"), std::string::npos) << fit.error().message;
  EXPECT_NE(fit.error().message.find("at least 50"), std::string::npos) << fit.error().message;
}

TEST(FitTest, NotFinitePointsAreCountedAndLeftOut) {
  Cloud cloud = sphere_cloud(Eigen::Vector3d(0, 0, 1), 0.05, 500);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < 480; ++i) cloud.points[i].x = nan;
  const auto fit = fit_object(cloud, all(cloud));
  ASSERT_FALSE(fit.ok());
  EXPECT_NE(fit.error().message.find("20 valid points (480 of 500 not finite)"), std::string::npos) << fit.error().message;

  // With enough finite points left, the NaNs are only skipped.
  Cloud some_nan = sphere_cloud(Eigen::Vector3d(0, 0, 1), 0.05, 2000);
  for (std::size_t i = 0; i < some_nan.size(); i += 3) some_nan.points[i].z = nan;
  const auto ok = fit_object(some_nan, all(some_nan));
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_EQ(ok->points, 2000u - 667u);
}

TEST(FitTest, IndexOutsideTheCloudAndBadConfigAreErrors) {
  const Cloud cloud = sphere_cloud(Eigen::Vector3d(0, 0, 1), 0.05, 200);
  std::vector<int> indices = all(cloud);
  indices.push_back(200);
  const auto outside = fit_object(cloud, indices);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.error().message.find("index 200 is outside the cloud (200 points)"), std::string::npos);
  indices.back() = -1;
  EXPECT_FALSE(fit_object(cloud, indices).ok());

  FitConfig bad;
  bad.epsilon_m = 0;
  const auto config = fit_object(cloud, all(cloud), bad);
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.error().message.find("ontology.epsilon_m"), std::string::npos);
  EXPECT_FALSE(fit_object(cloud, all(cloud), FitConfig{}, Eigen::Vector3d::Zero()).ok());
  EXPECT_FALSE(fit_object(cloud, {}).ok());
}

TEST(FitTest, AnExactHalfSphereIsASphereOfItsRadius) {
  const Cloud cloud = sphere_cloud(Eigen::Vector3d(0.05, -0.02, 0.9), 0.045, 4000);
  FitConfig every_point;  // the shape detection on all 4000, not the default subsample
  every_point.max_points = 4000;
  const auto fit = fit_object(cloud, all(cloud), every_point);
  ASSERT_TRUE(fit.ok()) << fit.error().message;
  ASSERT_GE(fit->best, 0);
  const Primitive& best = fit->shapes[static_cast<std::size_t>(fit->best)];
  EXPECT_EQ(best.kind, PrimitiveKind::kSphere);
  // Shape detection's own estimate, from a minimal sample (spheres are not refined): 1.1 mm off.
  EXPECT_NEAR(best.radius_m, 0.045, 0.0015);
  EXPECT_LT((best.point - Eigen::Vector3d(0.05, -0.02, 0.9)).norm(), 0.002);
  EXPECT_GT(best.indices.size(), 3000u);
  EXPECT_LT(best.rms_m, 0.001);
}

TEST(FitTest, TwoFacesOfABoxAreTwoPlanesWithTheirPoints) {
  // A box corner seen from the camera at the origin: faces x = 0.05 and z = 1.0, 1 mm noise.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> a(-0.05, 0.05), b(0.0, 0.1);
  std::normal_distribution<double> noise(0, 0.001);
  Cloud cloud;
  for (int i = 0; i < 2000; ++i) {
    PointT p;
    p.getVector3fMap() = Eigen::Vector3f(static_cast<float>(a(rng)), static_cast<float>(a(rng)), static_cast<float>(1.0 + noise(rng)));
    cloud.push_back(p);
    p.getVector3fMap() = Eigen::Vector3f(static_cast<float>(0.05 + b(rng) * 0.0 + noise(rng)), static_cast<float>(a(rng)),
                                         static_cast<float>(1.0 + b(rng)));
    cloud.push_back(p);
  }
  FitConfig planes_only;
  planes_only.detect_cylinder = planes_only.detect_sphere = planes_only.detect_cone = false;
  planes_only.max_points = 4000;  // all of them, not the default subsample
  const auto fit = fit_object(cloud, all(cloud), planes_only);
  ASSERT_TRUE(fit.ok()) << fit.error().message;
  ASSERT_EQ(fit->shapes.size(), 2u);
  for (const auto& plane : fit->shapes) {
    EXPECT_EQ(plane.kind, PrimitiveKind::kPlane);
    EXPECT_GT(plane.indices.size(), 1500u);
    EXPECT_LT(plane.rms_m, 0.0015) << plane.direction.transpose();
    const bool front = std::abs(plane.direction.z()) > 0.99, side = std::abs(plane.direction.x()) > 0.99;
    EXPECT_TRUE(front || side) << plane.direction.transpose();
    // Its points are its face's: even indices the front, odd ones the side.
    std::size_t own = 0;
    for (const int i : plane.indices) own += (i % 2 == 0) == front;
    EXPECT_GT(own, plane.indices.size() * 95 / 100);
  }
}

TEST(FitTest, SameSeedSameShapes) {
  const Cloud cloud = sphere_cloud(Eigen::Vector3d(0, 0, 1), 0.05, 3000);
  const auto a = fit_object(cloud, all(cloud)), b = fit_object(cloud, all(cloud));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->shapes.size(), b->shapes.size());
  for (std::size_t i = 0; i < a->shapes.size(); ++i) EXPECT_EQ(a->shapes[i].indices, b->shapes[i].indices);
}

}  // namespace
}  // namespace scenewatch::ontology
