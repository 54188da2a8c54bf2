// Observation histories from keyframes (the seed's planner behind NextBestView): a keyframe saw a
// point when the point is in front, inside its trusted image and at the depth it measured there,
// within the sensor model's tolerance; the faces of a box but the one it rests on.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scenewatch/planning/covariance_view.h"
#include "scenewatch/planning/observation_history.h"

namespace scenewatch::planning {
namespace {

// A camera at `eye` looking along +z (identity rotation) at a wall 1 m away, 64x48, f 50 px.
std::shared_ptr<const background::Keyframe> wall_keyframe(const Eigen::Vector3d& eye) {
  auto kf = std::make_shared<background::Keyframe>();
  kf->T_world_camera = Pose::Identity();
  kf->T_world_camera.translation() = eye;
  kf->intrinsics = Intrinsics{50.0, 50.0, 31.5, 23.5, 64, 48};
  kf->depth.width = 64;
  kf->depth.height = 48;
  kf->depth.depth_mm.assign(64 * 48, 1000);
  return kf;
}

TEST(ObservationHistory, AKeyframeSawWhatLiesOnItsDepth) {
  DepthAgreement agreement;  // structured light at 1 m: 3 x 1.9 mm + 2 cm
  const double tol = agreement.tolerance_m(1.0);
  EXPECT_NEAR(tol, 3.0 * agreement.sensor.sigma_z(1.0) + 0.02, 1e-12);
  const std::vector<Eigen::Vector3d> points = {
      {0.0, 0.0, 1.0},                 // on the wall: seen
      {0.1, 0.0, 1.0 + 0.9 * tol},     // within tolerance: seen
      {0.0, 0.0, 1.0 + 1.1 * tol},     // behind the wall: not seen
      {0.0, 0.0, 0.5},                 // in front of the wall, off its depth: not seen
      {0.0, 0.0, -1.0},                // behind the camera
      {2.0, 0.0, 1.0},                 // outside the image
      {(0.5 - 31.5) / 50.0, 0.0, 1.0}, // column 0: the untrusted border
  };
  const std::vector<std::shared_ptr<const background::Keyframe>> kfs = {wall_keyframe(Eigen::Vector3d::Zero()),
                                                                      wall_keyframe(Eigen::Vector3d(0.0, 0.0, 0.5))};
  const auto centres = observing_camera_centres(points, kfs, agreement);
  ASSERT_EQ(centres.size(), points.size());
  // The second camera's wall is at 1.5 m: it saw the point behind the first wall only if within
  // its tolerance there, which 1 + 1.1 tol is not.
  EXPECT_EQ(centres[0].size(), 1u);
  EXPECT_EQ(centres[0][0], Eigen::Vector3d::Zero());
  EXPECT_EQ(centres[1].size(), 1u);
  EXPECT_TRUE(centres[2].empty());
  EXPECT_TRUE(centres[3].empty());
  EXPECT_TRUE(centres[4].empty());
  EXPECT_TRUE(centres[5].empty());
  EXPECT_TRUE(centres[6].empty());
  const std::vector<Eigen::Vector3d> far = {{0.0, 0.0, 1.5}};
  EXPECT_EQ(observing_camera_centres(far, kfs, agreement)[0].size(), 1u) << "the second camera's wall";
}

TEST(ObservationHistory, BoxSurfaceLeavesOutTheFaceItRestsOn) {
  OrientedBox box;
  box.center = Eigen::Vector3d(0.0, 0.0, 0.05);
  box.extents = Eigen::Vector3d(0.1, 0.1, 0.1);
  const auto samples = box_surface_samples(box, Eigen::Vector3d::UnitZ(), 0.02);
  EXPECT_EQ(samples.size(), 5u * 25u);
  for (const auto& p : samples) {
    EXPECT_GT(p.z(), 1e-9) << "no sample on the bottom face";
    EXPECT_NEAR((p - box.center).cwiseAbs().maxCoeff(), 0.05, 1e-12) << "on a face";
  }
}

TEST(CovarianceView, MeasureNamesAndRules) {
  EXPECT_EQ(parse_covariance_measure("covariance"), WeightRule::kAllAxesLambda);
  EXPECT_EQ(parse_covariance_measure("covariance_321"), WeightRule::kMajorAxisUnit);
  EXPECT_EQ(parse_covariance_measure("covariance_322"), WeightRule::kMajorAxisLambda);
  EXPECT_FALSE(parse_covariance_measure("rear_side"));
  EXPECT_NE(all_measure_names().find("rear_side_entropy"), std::string::npos);
  EXPECT_NE(all_measure_names().find("covariance_322"), std::string::npos);
}

// Points seen from -x, and unseen ones: the prior pulls the camera to the unseen side.
TEST(CovarianceView, UnseenPointsPullTheCamera) {
  CovarianceViewRequest r;
  for (int i = 0; i < 10; ++i) {
    r.points_world.emplace_back(-0.05, 0.01 * i - 0.05, 0.0);
    r.observers_world.push_back({Eigen::Vector3d(-1.0, 0.0, 0.3)});
    r.points_world.emplace_back(0.05, 0.01 * i - 0.05, 0.0);
    r.observers_world.emplace_back();
  }
  r.radius_m = 0.7;
  auto answer = covariance_next_view(r);
  ASSERT_TRUE(answer.ok()) << answer.error().message;
  EXPECT_EQ(answer->observed, 10u);
  EXPECT_NEAR(answer->view.T_world_camera.translation().norm(), 0.7, 1e-9);
  EXPECT_GT(answer->view.T_world_camera.translation().x(), 0.5) << answer->why;
  EXPECT_NE(answer->why.find("3.23"), std::string::npos);
  r.observers_world.pop_back();
  EXPECT_FALSE(covariance_next_view(r).ok());
}

// The cap: unseen points under the object pull the sphere's minimum below the table; with a cap
// the answer stays within its angle of up, and is the cap's minimum (against a finer grid).
TEST(CovarianceView, ACapKeepsTheCameraAboveTheTable) {
  CovarianceViewRequest r;
  for (int i = 0; i < 10; ++i) {
    r.points_world.emplace_back(0.01 * i - 0.05, 0.0, 0.05);
    r.observers_world.push_back({Eigen::Vector3d(0.0, -0.3, 1.0)});
    r.points_world.emplace_back(0.01 * i - 0.05, 0.02, -0.05);
    r.observers_world.emplace_back();
  }
  r.radius_m = 0.7;
  auto free = covariance_next_view(r);
  ASSERT_TRUE(free.ok()) << free.error().message;
  const auto polar = [](const Eigen::Vector3d& x) { return std::acos(x.normalized().z()) * 180.0 / M_PI; };
  ASSERT_GT(polar(free->view.minimum.x_world), 90.0) << "the sphere's minimum is below the table: " << free->why;
  EXPECT_FALSE(free->capped);

  r.max_polar_deg = 60.0;
  auto capped = covariance_next_view(r);
  ASSERT_TRUE(capped.ok()) << capped.error().message;
  EXPECT_TRUE(capped->capped);
  EXPECT_NE(capped->why.find("below the cap"), std::string::npos) << capped->why;
  const Eigen::Vector3d x = capped->view.T_world_camera.translation();
  EXPECT_NEAR(x.norm(), 0.7, 1e-9);
  EXPECT_LE(polar(x), 60.0 + 1e-9);
  std::vector<Eigen::Matrix3d> covariances;
  for (std::size_t i = 0; i < r.points_world.size(); ++i) {
    covariances.push_back(depth_point_covariance(r.points_world[i], r.observers_world[i], r.sensor, r.focal_px, r.prior_sigma_m));
  }
  const PlaneQuadratic f = plane_quadratic(r.points_world, covariances, r.rule);
  double finest = std::numeric_limits<double>::infinity();
  for (double theta = 0.0; theta <= 60.0; theta += 0.25)
    for (double phi = 0.0; phi < 360.0; phi += 0.25) {
      const double t = theta * M_PI / 180.0, p = phi * M_PI / 180.0;
      finest = std::min(finest, f(0.7 * Eigen::Vector3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t))));
    }
  EXPECT_LE(f(x), finest + 1e-3 * std::abs(finest)) << "the 1-degree grid's minimum is the cap's to 0.1 %";

  // A minimum inside the cap is kept exactly; a cap angle out of range is refused.
  r.max_polar_deg = 179.0;
  auto wide = covariance_next_view(r);
  ASSERT_TRUE(wide.ok());
  EXPECT_FALSE(wide->capped);
  EXPECT_TRUE(wide->view.minimum.x_world.isApprox(free->view.minimum.x_world, 1e-12));
  r.max_polar_deg = 1e9;
  EXPECT_FALSE(covariance_next_view(r).ok());
}

}  // namespace
}  // namespace scenewatch::planning
