// A scripted scenario with exact ground truth: the simulator's object_moved (a set table seen along
// one arc, then a box moved and turned, seen along a second arc) goes through the working memory
// frame by frame, as a planner's stream would. The moved box must be reported gone where it stood
// and appeared where it was put; nothing else may disappear, and nothing else may appear on the
// table. (Away from the table, 3.5 m from the camera, the foot of a wall can still come out as an
// object: depth noise there is as large as a voxel. The test prints every event.)
#include <gtest/gtest.h>

#include "scenewatch/io/rgbd.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

TEST(Scenario, ObjectMovedIsGoneThenAppears) {
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/object_moved.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 320, 240), 8);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  const auto changes = simulator->changes();
  ASSERT_EQ(changes.size(), 1u);
  ASSERT_EQ(changes[0].moved.size(), 1u);
  const sim::ObjectDisplacement& moved = changes[0].moved[0];

  Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();  // the simulator's world has z up
  WorkingMemory memory(config);
  std::vector<Event> events[2];
  double stamp = 0.0;
  for (std::size_t phase = 0; phase < 2; ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      Intrinsics K = scenario.intrinsics;
      auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, K);
      ASSERT_TRUE(cloud.ok()) << cloud.error().message;
      Frame frame;
      frame.cloud = *cloud;
      frame.T_world_camera = rendered.truth.T_world_camera_reported;
      frame.intrinsics = K;
      frame.stamp_s = stamp += 0.1;
      auto result = memory.process(frame);
      ASSERT_TRUE(result.ok()) << result.error().message;
      events[phase].insert(events[phase].end(), result->events.begin(), result->events.end());
    }
  }
  auto of_kind = [](const std::vector<Event>& list, EventKind kind, double min_score) {
    std::vector<Event> out;
    for (const auto& e : list)
      if (e.kind == kind && e.score >= min_score) out.push_back(e);
    return out;
  };
  auto distance_xy = [](const Event& e, const Pose& T_world_object) {
    return (e.centroid_world.head<2>() - T_world_object.translation().head<2>()).norm();
  };
  for (const auto& e : events[1]) {
    std::printf("after the move: %s score %.2f at (%.3f, %.3f, %.3f)\n", to_string(e.kind), e.score, e.centroid_world.x(),
                e.centroid_world.y(), e.centroid_world.z());
  }
  std::printf("the box (id %d) stood at (%.3f, %.3f) and was put at (%.3f, %.3f)\n", moved.id,
              moved.T_world_before.translation().x(), moved.T_world_before.translation().y(),
              moved.T_world_after.translation().x(), moved.T_world_after.translation().y());

  EXPECT_TRUE(of_kind(events[0], EventKind::kObjectGone, 0.0).empty()) << "nothing leaves while the table is static";
  const auto gone = of_kind(events[1], EventKind::kObjectGone, 0.0);
  ASSERT_EQ(gone.size(), 1u) << "only the moved box is gone";
  // Centroids are of the visible surface, the truth is the box's base centre: a few cm apart.
  EXPECT_LT(distance_xy(gone[0], moved.T_world_before), 0.08);
  // On the table: inside its footprint (plus the tolerance of a visible-surface centroid), above its top.
  const Pose T_world_table = scenario.table.T_world_support();
  std::vector<Event> on_table;
  for (const auto& e : of_kind(events[1], EventKind::kObjectAppeared, 0.0)) {
    const Eigen::Vector3d p = T_world_table.inverse() * e.centroid_world;
    if (p.z() > 0 && std::abs(p.x()) < scenario.table.size_m.x() / 2 + 0.05 && std::abs(p.y()) < scenario.table.size_m.y() / 2 + 0.05) {
      on_table.push_back(e);
    }
  }
  ASSERT_EQ(on_table.size(), 1u) << "one object appears on the table";
  EXPECT_GE(on_table[0].score, 0.9) << "where the table had been seen bare: space seen free";
  EXPECT_LT(distance_xy(on_table[0], moved.T_world_after), 0.08);
}

}  // namespace
}  // namespace scenewatch::pipeline
