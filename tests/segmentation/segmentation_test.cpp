// Segmentation on synthetic scenes with exact answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "scenewatch/segmentation/label_scoring.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::segmentation {
namespace {

// A 1 m x 0.8 m table top at z = 0 (world z up) with boxes and a cylinder on it, sampled densely,
// with 2 mm of noise. labels: 1 table, 10*k for object k.
struct Scene {
  Cloud cloud;
  std::vector<std::uint32_t> labels;
};

void add_point(Scene& s, const Eigen::Vector3f& p, std::uint32_t label, std::mt19937& rng) {
  std::normal_distribution<float> noise(0.f, 0.002f);
  PointT q;
  q.x = p.x() + noise(rng);
  q.y = p.y() + noise(rng);
  q.z = p.z() + noise(rng);
  q.r = static_cast<std::uint8_t>(40 * label % 255);
  q.g = 100;
  q.b = 50;
  s.cloud.push_back(q);
  s.labels.push_back(label);
}

void add_box(Scene& s, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, std::uint32_t label, std::mt19937& rng) {
  const float step = 0.004f;
  for (float x = lo.x(); x <= hi.x(); x += step)
    for (float y = lo.y(); y <= hi.y(); y += step) add_point(s, {x, y, hi.z()}, label, rng);  // top
  for (float z = lo.z() + 0.012f; z <= hi.z(); z += step) {
    for (float x = lo.x(); x <= hi.x(); x += step) {
      add_point(s, {x, lo.y(), z}, label, rng);
      add_point(s, {x, hi.y(), z}, label, rng);
    }
    for (float y = lo.y(); y <= hi.y(); y += step) {
      add_point(s, {lo.x(), y, z}, label, rng);
      add_point(s, {hi.x(), y, z}, label, rng);
    }
  }
}

void add_cylinder(Scene& s, const Eigen::Vector2f& c, float r, float h, std::uint32_t label, std::mt19937& rng) {
  for (float z = 0.012f; z <= h; z += 0.004f)
    for (float a = 0; a < 2 * M_PI; a += 0.004f / r) add_point(s, {c.x() + r * std::cos(a), c.y() + r * std::sin(a), z}, label, rng);
}

Scene tabletop(std::uint32_t seed = 1) {
  Scene s;
  std::mt19937 rng(seed);
  for (float x = -0.5f; x <= 0.5f; x += 0.005f)
    for (float y = -0.4f; y <= 0.4f; y += 0.005f) add_point(s, {x, y, 0.f}, 1, rng);
  add_box(s, {-0.30f, -0.20f, 0.f}, {-0.18f, -0.05f, 0.10f}, 20, rng);
  add_box(s, {0.10f, 0.10f, 0.f}, {0.16f, 0.16f, 0.20f}, 30, rng);
  add_cylinder(s, {0.2f, -0.2f}, 0.04f, 0.12f, 40, rng);
  s.cloud.width = static_cast<std::uint32_t>(s.cloud.size());
  s.cloud.height = 1;
  return s;
}

Config upright() {
  Config c;
  c.up = Eigen::Vector3d::UnitZ();
  return c;
}

LabelScore score(const Scene& s, const Segmentation& seg) {
  std::vector<std::vector<int>> clusters;
  for (const auto& o : seg.objects) clusters.push_back(o.indices);
  return score_against_labels(clusters, seg.planes.empty() ? std::vector<int>{} : seg.planes[0].indices, s.labels);
}

TEST(Tabletop, FindsTheTableAndEveryObject) {
  const Scene s = tabletop();
  const Segmentation seg = segment(s.cloud, upright(), Eigen::Vector3d(0, -1, 1));
  ASSERT_EQ(seg.planes.size(), 1u);
  EXPECT_GT(seg.planes[0].normal.z(), 0.99);
  EXPECT_NEAR(seg.planes[0].d, 0.0, 0.005);
  EXPECT_NEAR(seg.planes[0].area_m2, 0.8, 0.05);
  ASSERT_EQ(seg.objects.size(), 3u);
  const LabelScore sc = score(s, seg);
  EXPECT_GT(sc.table_iou, 0.95);
  ASSERT_EQ(sc.objects.size(), 3u);
  for (const auto& o : sc.objects) EXPECT_GT(o.best_iou, 0.95) << "object " << o.object_id;
  // The tall box: 6 x 6 x 20 cm standing upright on the plane.
  for (const auto& o : seg.objects) {
    EXPECT_EQ(o.plane_id, 0);
    EXPECT_EQ(o.point_count, o.indices.size());
  }
}

TEST(Tabletop, OrientedBoxesAreAlignedWithThePlane) {
  const Scene s = tabletop();
  const Segmentation seg = segment(s.cloud, upright());
  ASSERT_EQ(seg.objects.size(), 3u);
  // The 6 x 6 x 20 cm box is the one whose centroid is near (0.13, 0.13).
  bool found = false;
  for (const auto& o : seg.objects) {
    if ((o.centroid.head<2>() - Eigen::Vector2d(0.13, 0.13)).norm() > 0.02) continue;
    found = true;
    const Eigen::Vector3d axis_z = o.box.rotation * Eigen::Vector3d::UnitZ();
    EXPECT_GT(axis_z.z(), 0.99);
    // Yaw: the box's sides are the world's x and y axes (a 45 degree box would be the PCA failure
    // on a square footprint).
    const Eigen::Vector3d axis_x = o.box.rotation * Eigen::Vector3d::UnitX();
    EXPECT_GT(std::max(std::abs(axis_x.x()), std::abs(axis_x.y())), 0.99);
    // Extents are min/max over points with 2 mm noise: up to 4 sigma beyond each face.
    constexpr double kNoise = 4 * 0.002;
    EXPECT_GE(o.box.extents.x(), 0.056);
    EXPECT_LE(o.box.extents.x(), 0.06 + 2 * kNoise);
    EXPECT_GE(o.box.extents.y(), 0.056);
    EXPECT_LE(o.box.extents.y(), 0.06 + 2 * kNoise);
    EXPECT_NEAR(o.box.extents.z(), 0.20 - 0.012, 0.01 + kNoise);
  }
  EXPECT_TRUE(found);
}

TEST(Tabletop, SameSeedSameResult) {
  const Scene s = tabletop();
  Config c;
  c.seed = 7;
  const Segmentation a = segment(s.cloud, c), b = segment(s.cloud, c);
  ASSERT_EQ(a.planes.size(), b.planes.size());
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.planes.size(); ++i) {
    EXPECT_EQ(a.planes[i].indices, b.planes[i].indices);
    EXPECT_EQ(a.planes[i].normal, b.planes[i].normal);
  }
  for (std::size_t i = 0; i < a.objects.size(); ++i) EXPECT_EQ(a.objects[i].indices, b.objects[i].indices);
}

TEST(Tabletop, UpVectorRejectsALargerWall) {
  Scene s = tabletop();
  std::mt19937 rng(3);
  // A 2 m x 1.5 m wall behind the table: larger than the table top.
  for (float x = -1.f; x <= 1.f; x += 0.005f)
    for (float z = -0.75f; z <= 0.75f; z += 0.005f) add_point(s, {x, 0.6f, z}, 0, rng);
  s.cloud.width = static_cast<std::uint32_t>(s.cloud.size());
  Config free_orientation;
  free_orientation.max_planes = 1;
  const Segmentation unconstrained = segment(s.cloud, free_orientation, Eigen::Vector3d(0, -1, 1));
  ASSERT_EQ(unconstrained.planes.size(), 1u);
  EXPECT_GT(std::abs(unconstrained.planes[0].normal.y()), 0.99) << "without an up-vector the wall wins";
  Config c = upright();
  c.max_planes = 1;
  const Segmentation constrained = segment(s.cloud, c, Eigen::Vector3d(0, -1, 1));
  ASSERT_EQ(constrained.planes.size(), 1u);
  EXPECT_GT(constrained.planes[0].normal.z(), 0.99) << "with up = z the table wins";
  EXPECT_EQ(constrained.objects.size(), 3u);
}

// A panel standing on the table but rising to 1 m (the foot of a wall, a cabinet's side) is part
// of a taller structure, not an object on the table; the three objects stay.
TEST(Tabletop, StructuresTallerThanObjectsAreNotObjects) {
  Scene s = tabletop();
  std::mt19937 rng(4);
  for (float y = -0.3f; y <= 0.3f; y += 0.004f)
    for (float z = 0.012f; z <= 1.0f; z += 0.004f) add_point(s, {0.45f, y, z}, 0, rng);
  s.cloud.width = static_cast<std::uint32_t>(s.cloud.size());
  const Segmentation seg = segment(s.cloud, upright(), Eigen::Vector3d(0, -1, 1.5));
  ASSERT_EQ(seg.planes.size(), 1u);
  EXPECT_EQ(seg.objects.size(), 3u);
  for (const auto& o : seg.objects) EXPECT_LT(o.centroid.x(), 0.3) << "no cluster on the panel at x = 0.45";
}

TEST(Tabletop, NormalPointsTowardsTheSensor) {
  const Scene s = tabletop();
  const Segmentation below = segment(s.cloud, Config{}, Eigen::Vector3d(0, 0, -1));
  ASSERT_GE(below.planes.size(), 1u);
  EXPECT_LT(below.planes[0].normal.z(), -0.99);
  EXPECT_TRUE(below.objects.empty()) << "seen from below, nothing stands on the table's lower side";
}

TEST(Tabletop, EmptyAndDegenerateInput) {
  Cloud empty;
  EXPECT_TRUE(segment(empty, Config{}).planes.empty());

  Cloud nans(10, 10);
  for (auto& p : nans.points) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  const Segmentation n = segment(nans, Config{});
  EXPECT_TRUE(n.planes.empty());
  EXPECT_TRUE(n.objects.empty());

  Cloud line;
  for (int i = 0; i < 1000; ++i) {
    PointT p;
    p.x = 0.001f * i;
    p.y = p.z = 0.f;
    line.push_back(p);
  }
  EXPECT_TRUE(segment(line, Config{}).planes.empty()) << "collinear points hold no plane";

  Cloud two;
  two.push_back(PointT());
  two.push_back(PointT());
  EXPECT_TRUE(segment(two, Config{}).planes.empty());
}

TEST(Tabletop, SmallPlanesAreNotSupportingPlanes) {
  Scene s;
  std::mt19937 rng(5);
  for (float x = 0; x <= 0.1f; x += 0.004f)
    for (float y = 0; y <= 0.1f; y += 0.004f) add_point(s, {x, y, 0.f}, 1, rng);
  s.cloud.width = static_cast<std::uint32_t>(s.cloud.size());
  s.cloud.height = 1;
  EXPECT_TRUE(segment(s.cloud, Config{}).planes.empty()) << "0.01 m^2 is below min_plane_area_m2";
}

TEST(Tabletop, ConfigValidationNamesTheKey) {
  Config c;
  c.voxel_size_m = -1;
  auto st = validate(c);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("segmentation.voxel_size_m"), std::string::npos);
  c = Config{};
  c.min_cluster_points = 10;
  c.max_cluster_points = 5;
  st = validate(c);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("min_cluster_points"), std::string::npos);
  EXPECT_TRUE(validate(Config{}).ok());
}

}  // namespace
}  // namespace scenewatch::segmentation
