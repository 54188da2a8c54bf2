// The foreground in the working memory: what it learnt about a handled object is saved with the
// model and is there again after a restart (a new WorkingMemory loading the model directory).
#include <gtest/gtest.h>

#include <cstdio>

#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

TEST(ForegroundMemoryTest, LearntDofsAndTheModelSurviveARestart) {
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/hand_picks_cup_upright.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_resolution(*loaded, 320, 240);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  WorkingMemory memory{Config{}};
  for (int f = 0; f < simulator->frame_count(0); ++f) {
    auto frame = sim::as_frame(simulator->render(0, f), scenario.intrinsics, f / 30.0);
    ASSERT_TRUE(frame.ok());
    ASSERT_TRUE(memory.process(*frame).ok());
  }
  auto foreground_of = [](const SceneSnapshot& s) {
    std::vector<TrackedObject> out;
    for (const auto& o : s.objects)
      if (o.foreground) out.push_back(o);
    return out;
  };
  const auto before = foreground_of(*memory.snapshot());
  ASSERT_EQ(before.size(), 1u) << "the cup, promoted";
  // Stats count the object list a planner gets (GetObjects): the promoted cup with the rest.
  EXPECT_EQ(memory.stats().tracked_objects, memory.snapshot()->objects.size());
  const auto& handlings = before[0].foreground->handlings;
  for (const auto& h : handlings) std::printf("handling %.2f s .. %.2f s\n", h.start_s, h.end_s);
  ASSERT_GE(handlings.size(), 1u);
  EXPECT_GT(handlings[0].end_s, 0.0) << "the carry has ended";

  test::TempDir dir("foreground-restart");
  ASSERT_TRUE(memory.save(dir.path()).ok());
  WorkingMemory restarted{Config{}};
  ASSERT_TRUE(restarted.load(dir.path()).ok());
  const auto after = foreground_of(*restarted.snapshot());
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(restarted.stats().tracked_objects, restarted.snapshot()->objects.size());
  const ForegroundState& a = *after[0].foreground;
  const ForegroundState& b = *before[0].foreground;
  EXPECT_EQ(after[0].id, before[0].id);
  EXPECT_EQ(a.free, b.free);
  ASSERT_EQ(a.handlings.size(), b.handlings.size());
  EXPECT_EQ(a.handlings[0].moved, b.handlings[0].moved);
  EXPECT_NEAR(a.handlings[0].range[0], b.handlings[0].range[0], 1e-9);
  // The saved rotation is made orthonormal again on load (ICP's comes from float arithmetic).
  EXPECT_TRUE(a.T_world_object.isApprox(b.T_world_object, 1e-6));
  EXPECT_EQ(a.model_points, b.model_points);
  EXPECT_FALSE(a.visible) << "not seen since the restart";
  EXPECT_DOUBLE_EQ(a.promoted_s, b.promoted_s);
}

}  // namespace
}  // namespace scenewatch::pipeline
