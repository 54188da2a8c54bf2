// DarkSpace's rules on a hand-made map: a floor, unknown space above it, a camera whose every
// pixel is a hole (change/dark_space.h). The end-to-end case, the seed's removed glasses, is in
// tests/pipeline/stream_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "scenewatch/change/dark_space.h"
#include "scenewatch/change/mismatch.h"

namespace scenewatch::change {
namespace {

// A metre cube of 2 cm voxels over x, y in [-0.5, 0.5], z in [0, 1]: unknown, and with `floor`
// its lowest layer occupied.
background::DenseGrid room(bool floor) {
  background::DenseGrid g;
  g.origin = Eigen::Vector3d(-0.5, -0.5, 0.0);
  g.resolution = 0.02;
  g.nx = g.ny = g.nz = 50;
  g.state.assign(static_cast<std::size_t>(g.nx) * g.ny * g.nz, static_cast<std::uint8_t>(background::Occupancy::kUnknown));
  if (floor)
    for (long n = 0; n < static_cast<long>(g.nx) * g.ny; ++n) g.state[n] = static_cast<std::uint8_t>(background::Occupancy::kOccupied);
  return g;
}

// 64 x 48 pixels without depth, but for two in the top-left corner (inside the image border,
// where no ray is recorded): the camera measures depths from `nearest_m` to 2 m.
DepthView holes(float nearest_m = 0.3f) {
  DepthView d;
  d.K = centred_pinhole(64, 48, 60.0);
  d.z.assign(64 * 48, std::numeric_limits<float>::quiet_NaN());
  d.z[0] = nearest_m;
  d.z[1] = 2.0f;
  d.min_z = nearest_m;
  d.max_z = 2.0f;
  return d;
}

// A camera 0.9 m above the floor looking down at its centre, from `tilt_deg` off the vertical (a
// turn about the world x axis, the camera moved along y to keep the centre in view). A voxel is
// seen from another direction only from another place: turning in place changes no direction.
Pose looking_down(double tilt_deg) {
  Eigen::Matrix3d down;
  down.col(0) = Eigen::Vector3d::UnitX();
  down.col(1) = -Eigen::Vector3d::UnitY();
  down.col(2) = -Eigen::Vector3d::UnitZ();
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(tilt_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix() * down;
  T.translation() = Eigen::Vector3d(0.0, -0.9 * std::tan(tilt_deg * M_PI / 180.0), 0.9);
  return T;
}

// Three frames looking straight down at the floor, then one from 20 degrees off the vertical.
DarkSpace recorded_from_two_views(const background::DenseGrid& grid, const Config& config) {
  DarkSpace dark(0.02);
  for (int i = 0; i < 3; ++i) dark.record(grid, holes(), looking_down(0), config, 0);
  dark.record(grid, holes(), looking_down(20), config, 0);
  return dark;
}

std::size_t dark_count(const std::vector<DarkSpace::Voxel>& voxels) {
  return static_cast<std::size_t>(std::count_if(voxels.begin(), voxels.end(), [](const auto& v) { return v.dark; }));
}

TEST(DarkSpace, RaysThatMeetNoKnownSurfaceRecordNothing) {
  DarkSpace dark(0.02);
  const Config config;
  for (int i = 0; i < 3; ++i) dark.record(room(false), holes(), looking_down(0), config, 0);
  EXPECT_EQ(dark.size(), 0u);
}

TEST(DarkSpace, HolesTheSensorsRangeExplainsRecordNothing) {
  // A Kinect v1 in its default mode returns nothing under 0.8 m: a floor 0.9 m below the camera,
  // seen at up to 0.96 m along the image's rays, lies within the noise of the nearest depth it
  // ever returned.
  DarkSpace dark(0.02);
  const Config config;
  for (int i = 0; i < 3; ++i) dark.record(room(true), holes(0.95f), looking_down(0), config, 0);
  EXPECT_EQ(dark.size(), 0u);
}

TEST(DarkSpace, DarkOnlyFromTwoDirectionsAndEnoughFrames) {
  DarkSpace dark(0.02);
  const Config config;  // persistence_frames 3
  const background::DenseGrid grid = room(true);
  for (int i = 0; i < 3; ++i) dark.record(grid, holes(), looking_down(0), config, 0);
  const auto one_view = dark.in_grid(grid, 0, config.persistence_frames);
  EXPECT_GT(one_view.size(), 100u) << "the unknown space in front of the floor is recorded";
  EXPECT_EQ(dark_count(one_view), 0u) << "three frames from one direction: a reflection or a dark patch";
  // Nothing within the tolerance in front of the floor: a dark patch of the floor is no space.
  for (const auto& v : one_view) EXPECT_GT(v.center_world.z(), 0.02 + 0.03) << v.center_world.transpose();

  dark.record(grid, holes(), looking_down(20), config, 0);
  const auto two_views = dark.in_grid(grid, 0, config.persistence_frames);
  EXPECT_GT(dark_count(two_views), 0u) << "crossed from directions 20 degrees apart, in four frames";
  EXPECT_EQ(dark_count(dark.in_grid(grid, 1, config.persistence_frames)), 0u) << "dark to the camera whose rays crossed it only";
  EXPECT_EQ(dark_count(dark.in_grid(grid, 0, 5)), 0u) << "four frames, not five";
}

TEST(DarkSpace, SeenThroughThenDarkAgainIsNeverDark) {
  const Config config;
  const background::DenseGrid grid = room(true);
  DarkSpace dark = recorded_from_two_views(grid, config);
  const auto before = dark.in_grid(grid, 0, config.persistence_frames);
  const auto first_dark = std::find_if(before.begin(), before.end(), [](const auto& v) { return v.dark; });
  ASSERT_NE(first_dark, before.end());
  const std::uint64_t key = first_dark->key;
  // Seen through once (the object left) it stays dark: what filled it is gone, and the change
  // detection needs it for a few frames to confirm that.
  dark.seen_through(key);
  auto has = [&](const std::vector<DarkSpace::Voxel>& voxels) {
    return std::any_of(voxels.begin(), voxels.end(), [&](const auto& v) { return v.key == key && v.dark; });
  };
  EXPECT_TRUE(has(dark.in_grid(grid, 0, config.persistence_frames)));
  // Crossed dark again after it was seen through: air in front of something that does not
  // return, never an object.
  dark.record(grid, holes(), looking_down(0), config, 0);
  EXPECT_FALSE(has(dark.in_grid(grid, 0, config.persistence_frames)));
  EXPECT_LT(dark.dark_voxels(config.persistence_frames), dark_count(before));
}

TEST(DarkSpace, OnlyTheVoxelsInsideTheGridAsked) {
  const Config config;
  const background::DenseGrid grid = room(true);
  const DarkSpace dark = recorded_from_two_views(grid, config);
  const auto all = dark.in_grid(grid, 0, config.persistence_frames);
  ASSERT_FALSE(all.empty());
  // The same room's left half (x < 0): the voxels there, and no others.
  background::DenseGrid left = grid;
  left.nx = 25;
  left.state.assign(static_cast<std::size_t>(left.nx) * left.ny * left.nz, static_cast<std::uint8_t>(background::Occupancy::kUnknown));
  const auto half = dark.in_grid(left, 0, config.persistence_frames);
  const auto in_left = std::count_if(all.begin(), all.end(), [](const auto& v) { return v.center_world.x() < 0; });
  EXPECT_EQ(static_cast<long>(half.size()), in_left);
  EXPECT_GT(in_left, 0);
  for (const auto& v : half) EXPECT_LT(v.center_world.x(), 0.0);
  // A grid a metre away holds none of them.
  background::DenseGrid away = grid;
  away.origin.x() += 1.0;
  EXPECT_TRUE(dark.in_grid(away, 0, config.persistence_frames).empty());
}

TEST(DarkSpace, ForgetAndReset) {
  const Config config;
  const background::DenseGrid grid = room(true);
  DarkSpace dark = recorded_from_two_views(grid, config);
  const auto voxels = dark.in_grid(grid, 0, config.persistence_frames);
  ASSERT_FALSE(voxels.empty());
  const std::size_t n = dark.size();
  dark.forget({voxels.front().center_world});
  EXPECT_EQ(dark.size(), n - 1);
  dark.reset();
  EXPECT_EQ(dark.size(), 0u);
}

}  // namespace
}  // namespace scenewatch::change
