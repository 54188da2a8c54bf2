// Unit tests of the change module: tolerance, cameras, the map path on constructed scenes,
// the persistence filter and bad input.
#include <gtest/gtest.h>

#include "scenewatch/change/diff.h"
#include "scenewatch/change/persistence.h"
#include "scenewatch/io/rgbd.h"
#include "test_data.h"

namespace scenewatch::change {
namespace {

// An organized synthetic view of a plane at depth `z_plane`, with an optional box of points
// standing in front of it (a fronto-parallel square of side `box_m` at depth `z_box`).
CloudPtr plane_view(const Intrinsics& K, float z_plane, float z_box = 0, float box_m = 0, float box_x = 0) {
  auto cloud = std::make_shared<Cloud>();
  cloud->width = K.width;
  cloud->height = K.height;
  cloud->is_dense = false;
  cloud->points.resize(static_cast<std::size_t>(K.width) * K.height);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const float rx = static_cast<float>((u - K.cx) / K.fx), ry = static_cast<float>((v - K.cy) / K.fy);
      float z = z_plane;
      if (box_m > 0 && std::abs(rx * z_box - box_x) < box_m / 2 && std::abs(ry * z_box) < box_m / 2) z = z_box;
      PointT& p = cloud->at(u, v);
      p.x = rx * z;
      p.y = ry * z;
      p.z = z;
      p.r = z == z_plane ? 200 : 30;
      p.g = 100;
      p.b = 50;
    }
  return cloud;
}

Intrinsics small_camera() { return Intrinsics{262.5, 262.5, 159.5, 119.5, 320, 240}; }

Frame frame_of(CloudPtr cloud) {
  Frame f;
  f.cloud = std::move(cloud);
  return f;
}

TEST(Change, ToleranceGrowsWithDepthLikeKinectNoise) {
  Config c;
  EXPECT_DOUBLE_EQ(tolerance_m(c, 0.5), c.min_tolerance_m);  // 3 sigma = 3.7 mm < 1 cm
  EXPECT_NEAR(tolerance_m(c, 3.0), 3 * (0.0012 + 0.0019 * 2.6 * 2.6), 1e-12);
  EXPECT_GT(tolerance_m(c, 4.0), tolerance_m(c, 3.0));
}

TEST(Change, IntrinsicsAreFittedFromAnOrganizedCloud) {
  const Intrinsics K = small_camera();
  auto fitted = io::estimate_intrinsics(*plane_view(K, 1.0f, 0.6f, 0.2f));
  ASSERT_TRUE(fitted.ok()) << fitted.error().message;
  EXPECT_NEAR(fitted->fx, K.fx, 1e-2);
  EXPECT_NEAR(fitted->cy, K.cy, 1e-2);
  Cloud flat = *plane_view(K, 1.0f);
  flat.width = static_cast<std::uint32_t>(flat.size());
  flat.height = 1;
  EXPECT_FALSE(io::estimate_intrinsics(flat).ok());
}

TEST(Change, SameCameraBoxAddedThenRemoved) {
  const Intrinsics K = small_camera();
  auto empty = plane_view(K, 1.2f), with_box = plane_view(K, 1.2f, 0.9f, 0.1f);
  auto added = diff(frame_of(empty), frame_of(with_box));
  ASSERT_TRUE(added.ok()) << added.error().message;
  EXPECT_EQ(added->method, DiffMethod::kSameCamera);
  ASSERT_EQ(added->events.size(), 1u);
  const Event& e = added->events[0];
  EXPECT_EQ(e.kind, EventKind::kObjectAdded);
  EXPECT_NEAR(e.centroid_world.z(), 0.9, 1e-3);
  EXPECT_NEAR(e.box_world.max.x() - e.box_world.min.x(), 0.1, 0.01);
  EXPECT_TRUE(e.indices_before.empty());
  // About every pixel of the box (its one-pixel rim fails the neighbour test).
  EXPECT_GT(e.indices_after.size(), 0.85 * 29 * 29);
  ASSERT_TRUE(e.region.has_value());
  EXPECT_NEAR(e.region->width, 29, 2);

  auto removed = diff(frame_of(with_box), frame_of(empty));
  ASSERT_TRUE(removed.ok());
  ASSERT_EQ(removed->events.size(), 1u);
  EXPECT_EQ(removed->events[0].kind, EventKind::kObjectRemoved);
  EXPECT_FALSE(removed->events[0].indices_before.empty());

  auto same = diff(frame_of(with_box), frame_of(with_box));
  ASSERT_TRUE(same.ok());
  EXPECT_TRUE(same->events.empty());
}

TEST(Change, SameCameraMoveIsPaired) {
  const Intrinsics K = small_camera();
  auto here = plane_view(K, 1.2f, 0.9f, 0.1f, -0.15f), there = plane_view(K, 1.2f, 0.9f, 0.1f, 0.15f);
  auto moved = diff(frame_of(here), frame_of(there));
  ASSERT_TRUE(moved.ok());
  ASSERT_EQ(moved->events.size(), 1u);
  const Event& e = moved->events[0];
  EXPECT_EQ(e.kind, EventKind::kObjectMoved);
  ASSERT_TRUE(e.displacement_world.has_value());
  EXPECT_NEAR(e.displacement_world->x(), 0.3, 0.01);
  EXPECT_FALSE(e.indices_before.empty());
  EXPECT_FALSE(e.indices_after.empty());
}

TEST(Change, MapPathAgreesAndOcclusionClaimsNothing) {
  const Intrinsics K = small_camera();
  DiffOptions options;
  options.force_map = true;
  options.map.resolution_m = 0.01;
  auto empty = plane_view(K, 1.2f), with_box = plane_view(K, 1.2f, 0.9f, 0.1f);
  auto added = diff(frame_of(empty), frame_of(with_box), options);
  ASSERT_TRUE(added.ok()) << added.error().message;
  EXPECT_EQ(added->method, DiffMethod::kMap);
  ASSERT_EQ(added->events.size(), 1u);
  EXPECT_EQ(added->events[0].kind, EventKind::kObjectAdded);
  EXPECT_NEAR(added->events[0].centroid_world.z(), 0.9, 0.01);

  auto removed = diff(frame_of(with_box), frame_of(empty), options);
  ASSERT_TRUE(removed.ok());
  ASSERT_EQ(removed->events.size(), 1u);
  EXPECT_EQ(removed->events[0].kind, EventKind::kObjectRemoved);
  EXPECT_GT(removed->events[0].indices_before.size(), 500u) << "BEFORE's points in the voxels seen through";

  // A large board in front of the box hides it: the box is occluded, not removed. The board
  // itself stands in space BEFORE saw free, so it is added.
  auto board = plane_view(K, 1.2f, 0.6f, 0.4f);
  auto occluded = diff(frame_of(with_box), frame_of(board), options);
  ASSERT_TRUE(occluded.ok());
  ASSERT_EQ(occluded->events.size(), 1u);
  EXPECT_EQ(occluded->events[0].kind, EventKind::kObjectAdded);
  EXPECT_NEAR(occluded->events[0].centroid_world.z(), 0.6, 0.01);
}

TEST(Change, UnknownSpaceClaimsNothing) {
  // BEFORE saw only the left half of the plane: a box on the right stands in unknown space.
  const Intrinsics K = small_camera();
  auto half = plane_view(K, 1.2f);
  for (int v = 0; v < K.height; ++v)
    for (int u = K.width / 2; u < K.width; ++u) half->at(u, v).x = half->at(u, v).y = half->at(u, v).z = NAN;
  DiffOptions options;
  options.force_map = true;
  auto result = diff(frame_of(half), frame_of(plane_view(K, 1.2f, 0.9f, 0.1f, 0.2f)), options);
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result->events.empty());
}

TEST(Change, BadInputIsNamed) {
  const Intrinsics K = small_camera();
  auto ok = plane_view(K, 1.0f);
  auto nan = plane_view(K, 1.0f);
  for (auto& p : nan->points) p.x = p.y = p.z = NAN;
  auto r = diff(frame_of(ok), frame_of(nan));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("AFTER"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("no valid point"), std::string::npos);

  auto other = plane_view(Intrinsics{525, 525, 319.5, 239.5, 640, 480}, 1.0f);
  r = diff(frame_of(ok), frame_of(other));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("same size"), std::string::npos) << r.error().message;

  Frame posed = frame_of(ok);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2;  // not a rotation
  posed.T_world_camera = Pose(m);
  r = diff(posed, frame_of(ok));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("BEFORE"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("pose"), std::string::npos) << r.error().message;

  Frame empty;
  empty.cloud = std::make_shared<Cloud>();
  r = diff(empty, frame_of(ok));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("empty"), std::string::npos);

  DiffOptions bad;
  bad.change.persistence_frames = 0;
  r = diff(frame_of(ok), frame_of(ok), bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("change.persistence_frames"), std::string::npos);
}

ChangeCluster cluster_at(ChangeKind kind, const Eigen::Vector3d& c, double size = 0.08) {
  ChangeCluster k;
  k.kind = kind;
  k.centroid_world = c;
  k.box_world.min = c - Eigen::Vector3d::Constant(size / 2);
  k.box_world.max = c + Eigen::Vector3d::Constant(size / 2);
  k.mean_rgb = Eigen::Vector3d(200, 50, 50);
  return k;
}

TEST(Change, PersistenceNeedsConsistentFrames) {
  Config config;
  config.persistence_frames = 3;
  PersistenceFilter filter(config);
  const Eigen::Vector3d p(0.1, 0.2, 0.8);
  std::vector<ChangeCluster> pending;
  EXPECT_TRUE(filter.update({cluster_at(ChangeKind::kAdded, p)}, &pending).empty());
  EXPECT_EQ(pending.size(), 1u) << "an unconfirmed candidate is kept out of the model";
  EXPECT_TRUE(filter.update({cluster_at(ChangeKind::kAdded, p + Eigen::Vector3d(0.01, 0, 0))}, nullptr).empty());
  auto fired = filter.update({cluster_at(ChangeKind::kAdded, p)}, nullptr);
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_EQ(fired[0].kind, EventKind::kObjectAdded);
  EXPECT_EQ(filter.candidates(), 0u);

  // Flicker: seen, missed three times, seen: never confirmed.
  filter.reset();
  for (int i = 0; i < 4; ++i) {
    const bool seen = i % 4 == 0;
    auto out = filter.update(seen ? std::vector<ChangeCluster>{cluster_at(ChangeKind::kAdded, p)} : std::vector<ChangeCluster>{}, nullptr);
    EXPECT_TRUE(out.empty());
  }
  EXPECT_EQ(filter.candidates(), 0u);
  // Jumping around by more than the match distance: a new candidate each time.
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(filter.update({cluster_at(ChangeKind::kAdded, p + Eigen::Vector3d(0.2 * i, 0, 0))}, nullptr).empty());
  }
}

// Issue 31: the unconfirmed candidates are listed with ids a planner can target.
TEST(Change, PendingCandidatesKeepTheirIdsUntilConfirmed) {
  Config config;
  config.persistence_frames = 3;
  auto ids = std::make_shared<PendingIds>();
  PersistenceFilter filter(config, ids);
  const Eigen::Vector3d p(0.1, 0.2, 0.8), q(-0.3, 0.1, 0.8);
  EXPECT_TRUE(filter.pending().empty());
  filter.update({cluster_at(ChangeKind::kAdded, p)}, nullptr, nullptr, /*camera=*/2);
  auto listed = filter.pending();
  ASSERT_EQ(listed.size(), 1u);
  const std::uint64_t added_id = listed[0].id;
  EXPECT_EQ(added_id, 1u) << "ids count from 1";
  EXPECT_EQ(listed[0].kind, PendingKind::kAdded);
  EXPECT_EQ(listed[0].hits, 1);
  EXPECT_EQ(listed[0].hits_needed, 3);
  EXPECT_EQ(listed[0].camera, 2u);
  EXPECT_TRUE(listed[0].centroid_world.isApprox(p));
  EXPECT_TRUE(listed[0].box_world.contains(p));

  // Matched 1 cm away: the same id, its latest box; a removal elsewhere is a new candidate (five
  // times larger, so that it is no move partner the addition would wait for).
  const Eigen::Vector3d p2 = p + Eigen::Vector3d(0.01, 0, 0);
  filter.update({cluster_at(ChangeKind::kAdded, p2), cluster_at(ChangeKind::kRemoved, q, 0.4)}, nullptr, nullptr, 2);
  listed = filter.pending();
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[0].id, added_id);
  EXPECT_EQ(listed[0].hits, 2);
  EXPECT_TRUE(listed[0].centroid_world.isApprox(p2));
  const std::uint64_t removed_id = listed[1].id;
  EXPECT_EQ(removed_id, 2u);
  EXPECT_EQ(listed[1].kind, PendingKind::kRemoved);
  EXPECT_EQ(listed[1].hits, 1);

  // The third sighting confirms the addition: the change names the candidate, the list drops it.
  auto fired = filter.update({cluster_at(ChangeKind::kAdded, p)}, nullptr, nullptr, 2);
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_EQ(fired[0].kind, EventKind::kObjectAdded);
  EXPECT_EQ(fired[0].pending_ids, std::vector<std::uint64_t>{added_id});
  EXPECT_EQ(to_event(fired[0]).pending_ids, std::vector<std::uint64_t>{added_id});
  listed = filter.pending();
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].id, removed_id);

  // The removal, not seen again, is dropped after persistence_frames misses: the list empties.
  filter.update({}, nullptr, nullptr, 2);
  filter.update({}, nullptr, nullptr, 2);
  EXPECT_TRUE(filter.pending().empty());

  // A new candidate where the first one was gets a new id, never one given before; the ids are
  // shared with every filter that holds the same counter (one id names one change).
  filter.update({cluster_at(ChangeKind::kAdded, p + Eigen::Vector3d(0, 0.3, 0))}, nullptr, nullptr, 2);
  ASSERT_EQ(filter.pending().size(), 1u);
  EXPECT_EQ(filter.pending()[0].id, 3u);
  PersistenceFilter other(config, ids);
  other.update({cluster_at(ChangeKind::kAdded, p)}, nullptr);
  ASSERT_EQ(other.pending().size(), 1u);
  EXPECT_EQ(other.pending()[0].id, 4u);
  filter.reset();
  EXPECT_TRUE(filter.pending().empty());
  filter.update({cluster_at(ChangeKind::kAdded, p)}, nullptr);
  EXPECT_EQ(filter.pending()[0].id, 5u) << "a reset does not restart the ids";
}

TEST(Change, PersistencePairsAMoveConfirmedAFrameApart) {
  Config config;
  config.persistence_frames = 2;
  PersistenceFilter filter(config);
  const Eigen::Vector3d a(0.0, 0.0, 0.8), b(0.3, 0.0, 0.8);
  EXPECT_TRUE(filter.update({cluster_at(ChangeKind::kRemoved, a)}, nullptr).empty());
  // The removed side is ready; the added side (seen once) is coming: wait for it.
  EXPECT_TRUE(filter.update({cluster_at(ChangeKind::kRemoved, a), cluster_at(ChangeKind::kAdded, b)}, nullptr).empty());
  auto fired = filter.update({cluster_at(ChangeKind::kRemoved, a), cluster_at(ChangeKind::kAdded, b)}, nullptr);
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_EQ(fired[0].kind, EventKind::kObjectMoved);
  const Event e = to_event(fired[0]);
  ASSERT_TRUE(e.displacement_world.has_value());
  EXPECT_NEAR(e.displacement_world->x(), 0.3, 1e-9);
  EXPECT_EQ(e.pending_ids, (std::vector<std::uint64_t>{1, 2})) << "both halves: the removal, then the addition";
  EXPECT_TRUE(filter.pending().empty());
}

}  // namespace
}  // namespace scenewatch::change
