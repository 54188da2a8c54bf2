// The appearance memory: keyframe selection, eviction, the mesh and its rendering, persistence.
#include <gtest/gtest.h>

#include <cmath>

#include "scenewatch/background/appearance.h"
#include "scenewatch/io/cloud_io.h"
#include "test_data.h"

namespace scenewatch::background {
namespace {

Intrinsics small_camera() { return centred_pinhole(160, 120, 150); }

// A camera at T_world_camera looking at the world plane z = 0 (the camera's z axis must point at
// it); colour is a checkerboard of the plane's world coordinates.
Keyframe plane_keyframe(const Pose& T_world_camera) {
  Keyframe kf;
  kf.intrinsics = small_camera();
  kf.T_world_camera = T_world_camera;
  const Intrinsics& K = kf.intrinsics;
  kf.color.width = kf.depth.width = K.width;
  kf.color.height = kf.depth.height = K.height;
  kf.color.rgb.assign(3u * K.width * K.height, 0);
  kf.depth.depth_mm.assign(static_cast<std::size_t>(K.width) * K.height, 0);
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray = T_world_camera.linear() * Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const double t = -T_world_camera.translation().z() / ray.z();  // ray parameter = camera depth
      if (!(t > 0)) continue;
      const Eigen::Vector3d p = T_world_camera.translation() + t * ray;
      const std::size_t i = static_cast<std::size_t>(v) * K.width + u;
      kf.depth.depth_mm[i] = static_cast<std::uint16_t>(std::lround(t * 1000));
      const bool dark = (static_cast<int>(std::floor(p.x() / 0.05)) + static_cast<int>(std::floor(p.y() / 0.05))) % 2;
      for (int k = 0; k < 3; ++k) kf.color.rgb[3 * i + k] = dark ? 40 : 220;
    }
  }
  return kf;
}

// A camera 1 m above the plane at (x, y), looking straight down, turned by yaw about its axis.
Pose looking_down(double x, double y, double yaw_deg = 0) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 1.0);
  return T;
}

TEST(AppearanceMemory, RendersTheDepthItWasGivenAndTheAnalyticDepthElsewhere) {
  AppearanceMemory memory;
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0, 0))).ok());
  const Intrinsics K = small_camera();
  // At the keyframe's own pose: its depth, inside the triangulated grid.
  const DepthMap same = memory.render_depth(looking_down(0, 0), K);
  std::size_t rendered = 0;
  for (float z : same.depth_m) {
    if (z > 0) {
      ++rendered;
      EXPECT_NEAR(z, 1.0, 0.002);
    }
  }
  EXPECT_GT(rendered, 0.9 * K.width * K.height);
  // From a pose 5 cm aside and tilted by 10 degrees, where the keyframe's patch covers it.
  Pose tilted = looking_down(0.05, 0.0);
  tilted.linear() = tilted.linear() * Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const DepthMap other = memory.render_depth(tilted, K);
  const Keyframe truth = plane_keyframe(tilted);
  std::size_t compared = 0;
  for (std::size_t i = 0; i < other.depth_m.size(); ++i) {
    if (other.depth_m[i] > 0 && truth.depth.depth_mm[i] > 0) {
      ++compared;
      EXPECT_NEAR(other.depth_m[i], truth.depth.depth_mm[i] * 0.001, 0.003) << "pixel " << i;
    }
  }
  EXPECT_GT(compared, 0.5 * K.width * K.height);
}

TEST(AppearanceMemory, KeepsAViewOnlyWhenItIsNewEnough) {
  AppearanceConfig config;
  config.keyframe_min_translation_m = 0.10;
  config.keyframe_min_rotation_deg = 10;
  AppearanceMemory memory(config);
  EXPECT_TRUE(*memory.consider(plane_keyframe(looking_down(0, 0))));
  EXPECT_FALSE(*memory.consider(plane_keyframe(looking_down(0.05, 0))));      // 5 cm, same direction
  EXPECT_FALSE(*memory.consider(plane_keyframe(looking_down(0, 0, 5))));      // turned by 5 degrees
  EXPECT_TRUE(*memory.consider(plane_keyframe(looking_down(0.15, 0))));       // 15 cm
  EXPECT_TRUE(*memory.consider(plane_keyframe(looking_down(0, 0, 15))));      // turned by 15 degrees
  EXPECT_EQ(memory.size(), 3u);
}

TEST(AppearanceMemory, EvictsTheMostRedundantViewAndNeverTheNewest) {
  AppearanceConfig config;
  config.max_keyframes = 3;
  AppearanceMemory memory(config);
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0.0, 0))).ok());   // id 1
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0.5, 0))).ok());   // id 2
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0.52, 0))).ok());  // id 3, 2 cm from id 2
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(1.0, 0))).ok());   // id 4: over the limit
  std::vector<std::uint64_t> ids;
  for (const auto& kf : memory.keyframes()) ids.push_back(kf->id);
  // 2 and 3 are each other's nearest view; the older of the two goes.
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{1, 3, 4}));
  // The newest survives even when it is the redundant one.
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(1.001, 0))).ok());  // id 5, 1 mm from id 4
  ids.clear();
  for (const auto& kf : memory.keyframes()) ids.push_back(kf->id);
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{1, 3, 5}));
  // The memory budget evicts too.
  AppearanceConfig tight;
  tight.memory_budget_mb = 1;  // one 160x120 keyframe is ~0.1 MB of images plus its patch
  AppearanceMemory small(tight);
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(small.add(plane_keyframe(looking_down(0.2 * i, 0))).ok());
  EXPECT_LE(small.memory_bytes(), 1u << 20);
  EXPECT_LT(small.size(), 20u);
}

TEST(AppearanceMemory, MeshKeepsOnlyNewSurfaceAndRoundTripsThroughPly) {
  AppearanceMemory memory;
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0, 0))).ok());
  const std::size_t one = memory.mesh().triangles.size();
  ASSERT_GT(one, 1000u);
  // The same view again adds nothing; a view half off the first adds part of a patch.
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0, 0))).ok());
  EXPECT_EQ(memory.mesh().triangles.size(), one);
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0.4, 0))).ok());
  const ColoredMesh mesh = memory.mesh();
  EXPECT_GT(mesh.triangles.size(), one + one / 10);
  EXPECT_LT(mesh.triangles.size(), 2 * one);
  for (const auto& v : mesh.vertices) EXPECT_NEAR(v.z(), 0.0, 0.002);

  test::TempDir dir("mesh");
  ASSERT_TRUE(io::write_mesh_ply(dir / "background.ply", mesh).ok());
  auto back = io::read_mesh_ply(dir / "background.ply");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->triangles.size(), mesh.triangles.size());
  EXPECT_EQ(back->vertices.size(), mesh.vertices.size());
  EXPECT_EQ(back->colors[10], mesh.colors[10]);
  // The written mesh renders the same depth as the memory.
  const DepthMap from_file = render_mesh_depth(*back, looking_down(0.2, 0), small_camera());
  const DepthMap from_memory = memory.render_depth(looking_down(0.2, 0), small_camera());
  std::size_t both = 0;
  for (std::size_t i = 0; i < from_file.depth_m.size(); ++i) {
    if (from_file.depth_m[i] > 0 && from_memory.depth_m[i] > 0) {
      ++both;
      EXPECT_NEAR(from_file.depth_m[i], from_memory.depth_m[i], 0.002);
    }
  }
  EXPECT_GT(both, from_file.depth_m.size() / 2);
}

TEST(AppearanceMemory, SavesAndLoadsItsKeyframes) {
  AppearanceMemory memory;
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0, 0))).ok());
  ASSERT_TRUE(memory.add(plane_keyframe(looking_down(0.3, 0.1, 20))).ok());
  test::TempDir dir("keyframes");
  ASSERT_TRUE(memory.save(dir.path()).ok());
  AppearanceMemory loaded;
  ASSERT_TRUE(loaded.load(dir.path()).ok());
  ASSERT_EQ(loaded.size(), 2u);
  const auto a = memory.keyframes(), b = loaded.keyframes();
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_TRUE(a[k]->T_world_camera.isApprox(b[k]->T_world_camera, 1e-9));
    EXPECT_EQ(a[k]->depth.depth_mm, b[k]->depth.depth_mm);
    EXPECT_EQ(a[k]->color.rgb, b[k]->color.rgb);
    EXPECT_DOUBLE_EQ(a[k]->intrinsics.fx, b[k]->intrinsics.fx);
  }
  // A missing folder is an empty memory; a broken keyframe file is an error naming it.
  AppearanceMemory empty;
  EXPECT_TRUE(empty.load(dir / "absent").ok());
  EXPECT_EQ(empty.size(), 0u);
  std::filesystem::resize_file(dir / "keyframe-000002.depth.png", 10);
  AppearanceMemory broken;
  auto st = broken.load(dir.path());
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("keyframe-000002.depth.png"), std::string::npos) << st.error().message;
}

TEST(AppearanceMemory, RejectsKeyframesWhoseSizesDisagree) {
  AppearanceMemory memory;
  Keyframe kf = plane_keyframe(looking_down(0, 0));
  kf.depth.width = 80;
  auto id = memory.add(kf);
  ASSERT_FALSE(id.ok());
  EXPECT_NE(id.error().message.find("disagree"), std::string::npos);
  EXPECT_EQ(memory.size(), 0u);

  Frame unorganized;
  auto cloud = std::make_shared<Cloud>();
  cloud->push_back(PointT());
  unorganized.cloud = cloud;
  unorganized.source = "x.pcd";
  auto k = keyframe_from_frame(unorganized);
  ASSERT_FALSE(k.ok());
  EXPECT_NE(k.error().message.find("organized"), std::string::npos);
}

}  // namespace
}  // namespace scenewatch::background
