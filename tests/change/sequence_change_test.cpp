// Live sequences through the working memory: simulator scenarios rendered frame by frame with
// their reported poses, as a planner's stream would arrive. The geometric change events
// (OBJECT_ADDED / OBJECT_REMOVED / OBJECT_MOVED) are scored against the scenario's exact change
// truth: an event is right when its kind matches and its centroid lies within 10 cm (in the
// table plane) of where the object was put (added, moved) or stood (removed). A static sequence
// of 200 frames must raise none.
#include <gtest/gtest.h>

#include <cstdio>

#include "scenewatch/io/rgbd.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::change {
namespace {

bool is_geometric(EventKind k) {
  return k == EventKind::kObjectAdded || k == EventKind::kObjectRemoved || k == EventKind::kObjectMoved;
}

struct SequenceRun {
  std::vector<Event> events;  // geometric only, all phases
  std::vector<sim::ChangeTruth> truth;
  double mean_change_ms = 0;
};

SequenceRun run_sequence(const std::string& name, int frames, int width, int height) {
  SequenceRun run;
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios" / (name + ".yaml"));
  EXPECT_TRUE(loaded.ok());
  if (!loaded.ok()) return run;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, width, height), frames);
  auto simulator = sim::Simulator::create(scenario);
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return run;
  run.truth = simulator->changes();
  pipeline::Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  pipeline::WorkingMemory memory(config);
  double stamp = 0, change_ms = 0;
  std::size_t n = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, scenario.intrinsics);
      EXPECT_TRUE(cloud.ok());
      if (!cloud.ok()) return run;
      Frame frame;
      frame.cloud = *cloud;
      frame.T_world_camera = rendered.truth.T_world_camera_reported;
      frame.intrinsics = scenario.intrinsics;
      frame.stamp_s = stamp += 0.1;
      auto result = memory.process(frame);
      EXPECT_TRUE(result.ok());
      if (!result.ok()) return run;
      change_ms += result->change_ms;
      ++n;
      for (const auto& e : result->events) {
        if (!is_geometric(e.kind)) continue;
        std::printf("  %s phase %zu frame %d: %s at (%.3f, %.3f, %.3f) %s\n", name.c_str(), phase, f, to_string(e.kind),
                    e.centroid_world.x(), e.centroid_world.y(), e.centroid_world.z(), e.detail.c_str());
        run.events.push_back(e);
      }
    }
  }
  run.mean_change_ms = n ? change_ms / n : 0;
  return run;
}

struct Score {
  std::size_t events = 0, right = 0, truths = 0, found = 0;
};

Score score(const SequenceRun& run) {
  struct Want {
    EventKind kind;
    Eigen::Vector2d xy;
    std::optional<Eigen::Vector3d> displacement;
  };
  std::vector<Want> wants;
  for (const auto& c : run.truth) {
    for (const auto& o : c.added) wants.push_back({EventKind::kObjectAdded, o.T_world_object.translation().head<2>(), {}});
    for (const auto& o : c.removed)
      if (!o.object.transparent) wants.push_back({EventKind::kObjectRemoved, o.T_world_object.translation().head<2>(), {}});
    for (const auto& m : c.moved) wants.push_back({EventKind::kObjectMoved, m.T_world_after.translation().head<2>(), m.translation_world_m});
  }
  Score s;
  s.events = run.events.size();
  s.truths = wants.size();
  std::vector<char> found(wants.size(), 0);
  for (const auto& e : run.events) {
    bool right = false;
    for (std::size_t i = 0; i < wants.size(); ++i) {
      if (wants[i].kind != e.kind || (e.centroid_world.head<2>() - wants[i].xy).norm() > 0.10) continue;
      right = true;
      found[i] = 1;
    }
    s.right += right ? 1 : 0;
  }
  for (char f : found) s.found += f;
  return s;
}

void print(const std::string& name, const Score& s, const SequenceRun& run) {
  std::printf("%-16s events %zu right %zu | truth %zu found %zu | precision %.2f recall %.2f | change detection %.1f ms/frame\n",
              name.c_str(), s.events, s.right, s.truths, s.found, s.events ? double(s.right) / s.events : 1.0,
              s.truths ? double(s.found) / s.truths : 1.0, run.mean_change_ms);
}

TEST(SequenceChange, AddedMovedAndRemovedObjectsAreReportedOnce) {
  for (const char* name : {"cup_added", "object_moved", "glasses_removed"}) {
    const SequenceRun run = run_sequence(name, 12, 320, 240);
    const Score s = score(run);
    print(name, s, run);
    EXPECT_EQ(s.right, s.events) << name << ": every event is a true change";
    EXPECT_EQ(s.found, s.truths) << name << ": every true change with depth is found";
  }
}

TEST(SequenceChange, StaticSequenceOf200FramesRaisesNothing) {
  // clutter: twelve objects close together, many occlusions, a transparent glass, half a circle.
  const SequenceRun run = run_sequence("clutter", 200, 320, 240);
  print("clutter (static)", score(run), run);
  EXPECT_TRUE(run.events.empty());
}

}  // namespace
}  // namespace scenewatch::change
