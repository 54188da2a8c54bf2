// The appearance path inside the working memory: posed RGB-D frames of the simulator's cup_added
// build keyframes; after the cup is put on the table, APPEARANCE_CHANGE events arise where it
// stands, and not while nothing changed; after a few frames the change is adopted into the
// memory and no longer reported. The keyframes survive save and load.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

Frame posed_frame(const sim::SimFrame& rendered, const Intrinsics& K, double stamp) {
  auto frame = sim::as_frame(rendered, K, stamp);
  EXPECT_TRUE(frame.ok());
  return frame.ok() ? *frame : Frame{};
}

TEST(AppearancePipeline, CupAddedIsOneEventWithTheSurpriseAsEvidence) {
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/cup_added.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 320, 240), 12);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  const Eigen::Vector3d cup(-0.15, -0.08, 0.8);  // from cup_added.yaml (table top at 0.75 m)

  Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  WorkingMemory memory(config);
  std::vector<Event> regions[2], events[2];
  std::vector<int> frames_with_regions;
  double stamp = 0;
  Frame last;
  for (std::size_t phase = 0; phase < 2; ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const Frame frame = posed_frame(simulator->render(phase, f), scenario.intrinsics, stamp += 0.1);
      auto result = memory.process(frame);
      ASSERT_TRUE(result.ok()) << result.error().message;
      if (phase == 0 && f > 0) {
        ASSERT_TRUE(result->surprise) << "frame " << f << " had a pose and keyframes existed";
        EXPECT_GT(result->surprise->map.known_pixels, 0u);
      }
      if (result->surprise) {
        for (const auto& e : result->surprise->events) {
          regions[phase].push_back(e);
          if (phase == 1) frames_with_regions.push_back(f);
          std::printf("phase %zu frame %d: surprise region: %s\n", phase, f, e.detail.c_str());
        }
      }
      for (const auto& e : result->events) {
        events[phase].push_back(e);
        std::printf("phase %zu frame %d: EVENT %s %s\n", phase, f, to_string(e.kind), e.detail.c_str());
      }
      last = frame;
    }
  }
  // The surprise layer sees the cup, and only the cup.
  EXPECT_TRUE(regions[0].empty()) << "nothing changed in the first phase";
  ASSERT_FALSE(regions[1].empty()) << "the cup was not noticed";
  std::size_t at_cup = 0;
  for (const auto& e : regions[1]) {
    ASSERT_TRUE(e.region.has_value());
    EXPECT_GT(e.evidence.at("kl_peak_total"), 0.0);
    EXPECT_EQ(e.level, EventLevel::kMismatch);
    at_cup += (e.centroid_world.head<2>() - cup.head<2>()).norm() < 0.08 ? 1 : 0;
  }
  EXPECT_GE(at_cup, regions[1].size() * 8 / 10) << "regions away from the cup";
  EXPECT_GE(memory.stats().keyframes, 1u);
  // After adopt_after_frames (5) frames of the same change, the memory holds the cup and the
  // surprise stops.
  ASSERT_EQ(config.surprise.adopt_after_frames, 5);
  EXPECT_EQ(frames_with_regions.front(), 0);
  EXPECT_LE(frames_with_regions.back(), 5) << "the change was not adopted";
  // The stream says it once: the cup added (geometry), with the appearance evidence merged in.
  EXPECT_TRUE(events[0].empty());
  ASSERT_EQ(events[1].size(), 1u) << "one fact, one event";
  EXPECT_EQ(events[1][0].kind, EventKind::kObjectAdded);
  EXPECT_LT((events[1][0].centroid_world.head<2>() - cup.head<2>()).norm(), 0.08);
  ASSERT_EQ(events[1][0].evidence.count("appearance_kl_mean"), 1u) << "the surprise regions are its evidence";
  EXPECT_GT(events[1][0].evidence.at("appearance_kl_mean"), config.surprise.regions.threshold_low);

  // The keyframes and the mesh are saved with the model and come back.
  test::TempDir dir("appearance-model");
  ASSERT_TRUE(memory.save(dir.path()).ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "current" / "mesh.ply"));
  WorkingMemory restored(config);
  ASSERT_TRUE(restored.load(dir.path()).ok());
  EXPECT_EQ(restored.stats().keyframes, memory.stats().keyframes);
  // The objects' colour spread too (what a completed object's unseen side is predicted with).
  std::size_t spread = 0;
  for (const auto& o : memory.snapshot()->objects) {
    for (const auto& r : restored.snapshot()->objects) {
      if (r.id != o.id) continue;
      EXPECT_TRUE(r.cluster.rgb_covariance.isApprox(o.cluster.rgb_covariance)) << "object " << o.id;
      spread += o.cluster.rgb_covariance.trace() > 1.0f ? 1 : 0;
    }
  }
  EXPECT_GT(spread, 0u) << "the simulator's objects are shaded and textured: their colours vary";
  auto a = memory.surprise(last), b = restored.surprise(last);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ((*a)->events.size(), (*b)->events.size());
  EXPECT_EQ((*a)->map.known_pixels, (*b)->map.known_pixels);

  // Bad observations are refused with the reason; an unposed cloud file is not an image.
  Frame unorganized = last;
  auto flat = std::make_shared<Cloud>(*last.cloud);
  flat->width = static_cast<std::uint32_t>(flat->size());
  flat->height = 1;
  unorganized.cloud = flat;
  unorganized.intrinsics.reset();
  auto refused = memory.surprise(unorganized);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("organized"), std::string::npos) << refused.error().message;
  WorkingMemory empty(config);
  auto none = empty.surprise(last);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, ErrorCode::kNotFound);
}

// A described object's completed surface (WorkingMemory::set_known_surface, which the pipeline's
// describer feeds with the ontology's completion on GetObjects { describe }) enters the expected view of later
// frames: a can seen from the front, then from 90 degrees to its side, where the keyframe's mesh
// lacks its side. Here the surface is the can's true cylinder (the ontology's part is measured in
// ontology_test's CompletionInTheExpectedView); an id that is not in the scene contributes nothing.
TEST(AppearancePipeline, AKnownSurfaceOfADescribedObjectEntersTheExpectedView) {
  test::TempDir dir("known-surface");
  std::ofstream(dir / "far_side.yaml") << R"(name: far_side
seed: 3
objects:
  - {id: 2, name: can, shape: cylinder, radius_m: 0.033, height_m: 0.122, color: [210, 30, 30], position: [0.0, 0.0]}
phases:
  - name: front
    frames: 3
    camera: {type: static, position: [-0.7, 0.0, 1.2], target: [0.0, 0.0, 0.8]}
  - name: side
    frames: 1
    camera: {type: static, position: [0.0, -0.7, 1.2], target: [0.0, 0.0, 0.8]}
)";
  auto loaded = sim::load_scenario(dir / "far_side.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  auto simulator = sim::Simulator::create(sim::with_resolution(*loaded, 320, 240));
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  const Intrinsics K = simulator->scenario().intrinsics;
  // The can's whole surface every 4 mm: side and top (table top at 0.75 m).
  surprise::KnownSurface can;
  can.rgb = Eigen::Vector3f(210, 30, 30);
  for (double z = 0.75; z <= 0.872; z += 0.004)
    for (double a = 0; a < 2 * M_PI; a += 0.004 / 0.033) can.points_world.emplace_back(0.033 * std::cos(a), 0.033 * std::sin(a), z);
  for (double r = 0; r < 0.033; r += 0.004)
    for (double a = 0; a < 2 * M_PI; a += 0.004 / std::max(r, 0.004)) can.points_world.emplace_back(r * std::cos(a), r * std::sin(a), 0.872);

  for (const bool described : {false, true}) {
    SCOPED_TRACE(described ? "the can described" : "another id described");
    Config config;
    config.segmentation.up = Eigen::Vector3d::UnitZ();
    WorkingMemory memory(config);
    double stamp = 0;
    for (int f = 0; f < simulator->frame_count(0); ++f) {
      ASSERT_TRUE(memory.process(posed_frame(simulator->render(0, f), K, stamp += 0.1)).ok());
    }
    const auto scene = memory.snapshot();
    const TrackedObject* tracked = nullptr;
    for (const auto& o : scene->objects)
      if ((o.cluster.centroid.head<2>()).norm() < 0.05) tracked = &o;
    ASSERT_NE(tracked, nullptr) << "the can is tracked";
    memory.set_known_surface(described ? tracked->id : tracked->id + 1000, tracked->cluster.centroid, can);
    auto side = memory.process(posed_frame(simulator->render(1, 0), K, stamp += 0.1));
    ASSERT_TRUE(side.ok()) << side.error().message;
    ASSERT_TRUE(side->surprise);
    std::printf("%s: %zu expected-view pixels set by the known surface\n", described ? "can described" : "other id",
                side->surprise->known_surface_pixels);
    if (described) {
      EXPECT_GT(side->surprise->known_surface_pixels, 700u);  // measured 892
    } else {
      EXPECT_EQ(side->surprise->known_surface_pixels, 0u);
    }
  }
}

}  // namespace
}  // namespace scenewatch::pipeline
