// The measured misalignment of a frame against the map (issue 28): zero-ish for the simulator's
// exact poses, and the perturbation's size when the pose given with the frame is wrong by a known
// rigid motion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scenewatch/change/mismatch.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::change {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Measured {
  PoseAgreement pose;
  std::size_t evidence = 0;      // added points plus seen-through voxels
  double given_shift_m = 0.0;    // how far the given error moved the frame's points, RMS
};

// A map of the scenario's first frames (640x480, 2 cm), then its next frame placed with the given
// pose error (applied in the camera frame), compared with it.
Measured measure(const Pose& error_camera) {
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/clutter.yaml");
  EXPECT_TRUE(loaded.ok());
  if (!loaded.ok()) return {};
  auto simulator = sim::Simulator::create(sim::with_resolution(*loaded, 640, 480));
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return {};
  const Intrinsics K = simulator->scenario().intrinsics;
  background::OccupancyMap map(background::Config{});
  auto frame_at = [&](int i, Pose* T) {
    const sim::SimFrame f = simulator->render(0, i);
    *T = f.truth.T_world_camera_reported;
    auto cloud = io::rgbd_to_cloud(f.color, f.depth, K);
    EXPECT_TRUE(cloud.ok());
    return *cloud;
  };
  Pose T;
  for (int i = 0; i < 6; ++i) map.insert(*frame_at(i, &T), T, 2);
  const CloudConstPtr next = frame_at(8, &T);
  Config config;
  auto mm = mismatch_against_map(map, *next, T * error_camera, K, config);
  EXPECT_TRUE(mm.ok());
  if (!mm.ok()) return {};
  // How far the given error moved the frame's points that are compared with the map (RMS over
  // every 50th valid point within change.max_range_m).
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < next->size(); i += 50) {
    if (!is_valid(next->points[i]) || next->points[i].z > config.max_range_m) continue;
    const Eigen::Vector3d p = next->points[i].getVector3fMap().cast<double>();
    sum += ((T * error_camera * p) - (T * p)).squaredNorm();
    ++n;
  }
  Measured m{mm->pose, mm->added.size() + mm->missing.size(), n ? std::sqrt(sum / n) : 0.0};
  std::printf("pose error given: %.1f mm, %.2f deg, moving the points by %.1f mm RMS -> measured %.1f mm, %.2f deg, %.1f mm RMS, from %zu samples; evidence %zu\n",
              1000 * error_camera.translation().norm(), Eigen::AngleAxisd(error_camera.linear()).angle() * 180 / kPi,
              1000 * m.given_shift_m, 1000 * mm->pose.translation_m, mm->pose.rotation_deg, 1000 * mm->pose.rms_shift_m,
              mm->pose.samples, m.evidence);
  return m;
}

TEST(PoseAgreement, ExactPosesMeasureAlmostNothing) {
  const Measured m = measure(Pose::Identity());
  EXPECT_GT(m.pose.samples, 1000u);
  // The map's 2 cm voxels leave the fit a few millimetres to wander (6.2 mm measured).
  EXPECT_LT(m.pose.rms_shift_m, 0.008);
}

TEST(PoseAgreement, AWrongPoseIsMeasuredAtItsSize) {
  // 2 cm sideways and 1 degree about the vertical: what a drifting pose source gives.
  Pose error = Pose::Identity();
  error.translation() = Eigen::Vector3d(0.02, 0.0, 0.0);
  error.linear() = Eigen::AngleAxisd(1.0 * kPi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Measured m = measure(error);
  // Rotation and translation trade off against each other in one view; how far they move the
  // points is what counts: 40.4 mm measured against 47.6 mm given.
  EXPECT_NEAR(m.pose.rms_shift_m, m.given_shift_m, 0.25 * m.given_shift_m);
  EXPECT_EQ(m.evidence, 0u) << "a wrong pose is no change";
}

}  // namespace
}  // namespace scenewatch::change

namespace scenewatch::change {
namespace {

TEST(SurfaceWitness, ACameraClaimsOnlyAgainstWhatItHasSeen) {
  SurfaceWitness witness(0.02);
  auto cloud = std::make_shared<Cloud>();
  PointT p;
  p.x = 0.1f;
  p.y = 0.0f;
  p.z = 1.0f;
  cloud->push_back(p);
  witness.witness(*cloud, Pose::Identity(), /*camera=*/3);
  const Eigen::Vector3d seen(0.1, 0.0, 1.0), elsewhere(0.5, 0.0, 1.0);
  EXPECT_EQ(witness.seen(seen, 3), SurfaceWitness::Seen::kBySelf);
  EXPECT_EQ(witness.seen(seen, 4), SurfaceWitness::Seen::kByOthersOnly);
  EXPECT_EQ(witness.seen(elsewhere, 4), SurfaceWitness::Seen::kByNone);
  witness.witness(*cloud, Pose::Identity(), 4);
  EXPECT_EQ(witness.seen(seen, 4), SurfaceWitness::Seen::kBySelf);
  witness.forget({seen});
  EXPECT_EQ(witness.seen(seen, 3), SurfaceWitness::Seen::kByNone);
  // Bounded: beyond the limit the surfaces seen least recently go.
  SurfaceWitness small(0.02, 100);
  for (int i = 0; i < 200; ++i) {
    auto one = std::make_shared<Cloud>();
    PointT q;
    q.x = 0.05f * static_cast<float>(i);
    q.y = 0.0f;
    q.z = 1.0f;
    one->push_back(q);
    small.witness(*one, Pose::Identity(), 0);
  }
  EXPECT_LE(small.size(), 100u);
  EXPECT_EQ(small.seen(Eigen::Vector3d(0.05 * 199 + 0.001, 0, 1.0), 0), SurfaceWitness::Seen::kBySelf);
  EXPECT_EQ(small.seen(Eigen::Vector3d(0.001, 0, 1.0), 0), SurfaceWitness::Seen::kByNone);
}

// Voxels are kept in blocks of 4 x 4 x 4: neighbours in one block, and in the next block, are
// separate surfaces; forgetting one leaves the others, and a block emptied and filled again
// starts clean.
TEST(SurfaceWitness, NeighbouringVoxelsAreSeparateSurfaces) {
  SurfaceWitness witness(0.02);
  auto cloud = std::make_shared<Cloud>();
  for (float x : {0.001f, 0.021f, 0.081f}) {  // voxels 0 and 1 (one block), 4 (the next block)
    PointT p;
    p.x = x;
    p.y = 0.001f;
    p.z = 1.001f;
    cloud->push_back(p);
  }
  witness.witness(*cloud, Pose::Identity(), 1);
  EXPECT_EQ(witness.size(), 3u);
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.041, 0.001, 1.001), 1), SurfaceWitness::Seen::kByNone);
  witness.forget({Eigen::Vector3d(0.001, 0.001, 1.001)});
  EXPECT_EQ(witness.size(), 2u);
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.001, 0.001, 1.001), 1), SurfaceWitness::Seen::kByNone);
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.021, 0.001, 1.001), 1), SurfaceWitness::Seen::kBySelf);
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.081, 0.001, 1.001), 1), SurfaceWitness::Seen::kBySelf);
  witness.forget({Eigen::Vector3d(0.021, 0.001, 1.001), Eigen::Vector3d(0.081, 0.001, 1.001)});
  EXPECT_EQ(witness.size(), 0u);
  auto other = std::make_shared<Cloud>();
  other->push_back(cloud->points[1]);
  witness.witness(*other, Pose::Identity(), 2);
  double depth = 0.0;
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.021, 0.001, 1.001), 1, &depth), SurfaceWitness::Seen::kByOthersOnly);
  EXPECT_NEAR(depth, 1.001, 1e-6);
  EXPECT_EQ(witness.seen(Eigen::Vector3d(0.001, 0.001, 1.001), 2), SurfaceWitness::Seen::kByNone);
}

// The map's surface lies within the noise of the nearest depth it was seen at: one point of the
// world, seen from 3 m by one camera and from 1.2 m by another, keeps 1.2 m, whichever came first.
TEST(SurfaceWitness, KeepsTheNearestDepthEachSurfaceWasSeenAt) {
  SurfaceWitness witness(0.02);
  const Eigen::Vector3d world(0.11, 0.01, 3.01);
  auto seen_from = [&](double back_m) {
    Cloud cloud;
    PointT p;
    p.x = static_cast<float>(world.x());
    p.y = static_cast<float>(world.y());
    p.z = static_cast<float>(world.z() - back_m);  // camera frame: the camera at z = back_m
    cloud.push_back(p);
    Pose T = Pose::Identity();
    T.translation() = Eigen::Vector3d(0, 0, back_m);
    return std::make_pair(cloud, T);
  };
  double depth = -1;
  EXPECT_EQ(witness.seen(world, 0, &depth), SurfaceWitness::Seen::kByNone);
  EXPECT_EQ(depth, 0.0) << "no depth for a surface nobody saw";
  const auto [far, T_far] = seen_from(0.0);
  witness.witness(far, T_far, 0);
  witness.seen(world, 0, &depth);
  EXPECT_NEAR(depth, 3.01, 1e-6);
  const auto [near, T_near] = seen_from(1.81);
  witness.witness(near, T_near, 1);
  EXPECT_EQ(witness.seen(world, 0, &depth), SurfaceWitness::Seen::kBySelf);
  EXPECT_NEAR(depth, 1.2, 1e-6);
  witness.witness(far, T_far, 0);
  witness.seen(world, 1, &depth);
  EXPECT_NEAR(depth, 1.2, 1e-6) << "a farther sighting later does not widen it again";
}

}  // namespace
}  // namespace scenewatch::change
