// The image behind an unorganized cloud: recovered exactly from a depth image's pixels, made up
// as a virtual camera for scattered rays, and refused for clouds that are not one view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "scenewatch/core/image_grid.h"

namespace scenewatch {
namespace {

// A 160 x 120 depth image (fx 140, cx 79.5, cy 59.5) of a wall at 2 m with a box 0.5 m in front
// of it, with a hole of missing depth, as an organized cloud.
Cloud depth_image() {
  Cloud c;
  c.width = 160;
  c.height = 120;
  c.points.resize(c.width * c.height);
  const double f = 140, cx = 79.5, cy = 59.5;
  for (int v = 0; v < 120; ++v) {
    for (int u = 0; u < 160; ++u) {
      PointT& p = c.points[v * 160 + u];
      const bool hole = u > 100 && u < 120 && v > 10 && v < 30;
      if (hole) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float z = (u > 50 && u < 90 && v > 40 && v < 80) ? 1.5f : 2.0f;
      p.z = z;
      p.x = static_cast<float>((u - cx) * z / f);
      p.y = static_cast<float>((v - cy) * z / f);
      p.r = static_cast<std::uint8_t>(u), p.g = static_cast<std::uint8_t>(v), p.b = 7;
    }
  }
  return c;
}

// The valid points in a seeded random order, height 1.
Cloud shuffled(const Cloud& in, std::uint32_t seed) {
  Cloud out;
  for (const auto& p : in.points)
    if (is_valid(p)) out.push_back(p);
  std::mt19937 rng(seed);
  std::shuffle(out.points.begin(), out.points.end(), rng);
  out.width = static_cast<std::uint32_t>(out.size());
  out.height = 1;
  return out;
}

TEST(ImageGrid, ShuffledDepthImageComesBackExactly) {
  const Cloud image = depth_image();
  const Cloud cloud = shuffled(image, 3);
  const auto grid = recover_image_grid(cloud, Eigen::Vector3d::Zero());
  ASSERT_TRUE(grid.has_value());
  EXPECT_TRUE(grid->exact);
  EXPECT_NEAR(grid->K.fx, 140.0, 1e-3);
  EXPECT_NEAR(grid->K.fy, 140.0, 1e-3);
  EXPECT_NEAR(grid->K.cx, 79.5, 1e-3);
  EXPECT_NEAR(grid->K.cy, 59.5, 1e-3);
  EXPECT_EQ(grid->K.width, 160);
  EXPECT_EQ(grid->K.height, 120);
  // Every point has a pixel of its own, and the image is the one the cloud was made from.
  const Cloud organized = organized_cloud(cloud, *grid);
  ASSERT_EQ(organized.size(), image.size());
  std::size_t same = 0, valid = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const bool a = is_valid(image[i]), b = is_valid(organized[i]);
    EXPECT_EQ(a, b) << "pixel " << i;
    if (!a || !b) continue;
    ++valid;
    same += image[i].getVector3fMap() == organized[i].getVector3fMap() && image[i].r == organized[i].r;
  }
  EXPECT_EQ(same, valid);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(grid->point[grid->pixel[i]], static_cast<int>(i));
}

TEST(ImageGrid, SensorPoseFromTheViewpointIsUsed) {
  // The same image moved into a world frame: the camera 1 m up, turned 30 degrees about y.
  const Eigen::Quaternionf q(Eigen::AngleAxisf(0.5236f, Eigen::Vector3f::UnitY()));
  const Eigen::Vector3f t(0.3f, 1.0f, -0.2f);
  Cloud cloud = shuffled(depth_image(), 5);
  for (auto& p : cloud.points) p.getVector3fMap() = q * p.getVector3fMap() + t;
  const auto wrong = recover_image_grid(cloud, Eigen::Vector3d::Zero());
  EXPECT_TRUE(!wrong || !wrong->exact) << "seen from the wrong place, the rays fall on no lattice";
  const auto grid = recover_image_grid(cloud, t.cast<double>(), q);
  ASSERT_TRUE(grid.has_value());
  EXPECT_TRUE(grid->exact);
  EXPECT_NEAR(grid->K.fx, 140.0, 0.05);
  EXPECT_EQ(grid->K.width, 160);
  EXPECT_EQ(grid->K.height, 120);
}

TEST(ImageGrid, ScatteredRaysGetAVirtualCameraAsFineAsThePoints) {
  // A voxel-filtered or stereo cloud: rays off any lattice. 19k points over the image's field of view.
  Cloud cloud = shuffled(depth_image(), 7);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  for (auto& p : cloud.points) {
    const float s = p.z / 140.0f;
    p.x += jitter(rng) * s;
    p.y += jitter(rng) * s;
  }
  const auto grid = recover_image_grid(cloud, Eigen::Vector3d::Zero());
  ASSERT_TRUE(grid.has_value());
  EXPECT_FALSE(grid->exact);
  // One pixel per point over the area the points cover: close to the camera's own 140.
  EXPECT_GT(grid->K.fx, 110.0);
  EXPECT_LT(grid->K.fx, 170.0);
  std::size_t with_pixel = 0;
  for (int px : grid->pixel) with_pixel += px >= 0;
  EXPECT_EQ(with_pixel, cloud.size()) << "every point in front falls on the virtual image";
}

TEST(ImageGrid, TwoViewsMergedAreNotOneImage) {
  // The wall and box seen from the front, merged with a second view of the same wall from behind
  // it and offset: half the points hide behind nearer ones along their rays.
  const Cloud front = shuffled(depth_image(), 1);
  Cloud merged = front;
  for (const auto& p : front.points) {
    PointT q = p;
    q.z = p.z + 1.0f;
    q.x = p.x * q.z / p.z;
    q.y = p.y * q.z / p.z;
    merged.push_back(q);
  }
  merged.width = static_cast<std::uint32_t>(merged.size());
  merged.height = 1;
  EXPECT_FALSE(recover_image_grid(merged, Eigen::Vector3d::Zero()).has_value());
}

TEST(ImageGrid, PointsBehindTheSensorOrTooFewGiveNoGrid) {
  Cloud cloud = shuffled(depth_image(), 2);
  for (std::size_t i = 0; i < cloud.size(); i += 50) cloud.points[i].z = -1.0f;
  EXPECT_FALSE(recover_image_grid(cloud, Eigen::Vector3d::Zero()).has_value());
  Cloud few;
  for (int i = 0; i < 50; ++i) few.push_back(depth_image().points[i * 100]);
  few.width = 50;
  few.height = 1;
  EXPECT_FALSE(recover_image_grid(few, Eigen::Vector3d::Zero()).has_value());
  EXPECT_FALSE(recover_image_grid(depth_image(), Eigen::Vector3d::Zero()).has_value()) << "already organized";
}

}  // namespace
}  // namespace scenewatch
