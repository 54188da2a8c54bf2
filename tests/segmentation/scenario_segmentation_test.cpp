// Simulator scenarios with exact labels: stacked and touching objects come apart, whole, in
// every frame of a quarter circle around the table, and stacked ones say what they stand on.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <map>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/segmentation/label_scoring.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::segmentation {
namespace {

// Objects with fewer visible points than this are hidden, not missed.
constexpr std::size_t kMinVisiblePoints = 300;
constexpr float kMaxRangeM = 2.5f;

struct SceneRun {
  std::size_t frames = 0, objects = 0, matched = 0, clusters = 0, correct = 0;
  // Per frame: for each labelled object id, the index of its best cluster (-1: none).
  std::vector<std::map<std::uint32_t, int>> best;
  std::vector<Segmentation> segmentations;
};

SceneRun run_scenario(const std::string& name, int frame_step = 1, Config config = Config{}) {
  SceneRun run;
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios" / (name + ".yaml"));
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
  if (!loaded.ok()) return run;
  auto simulator = sim::Simulator::create(*loaded);
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return run;
  for (int f = 0; f < simulator->frame_count(0); f += frame_step) {
    const sim::SimFrame rendered = simulator->render(0, f);
    auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
    EXPECT_TRUE(cloud.ok());
    if (!cloud.ok()) return run;
    // Only what the sensor saw can be found (the glass has colour but no depth).
    std::vector<std::uint32_t> labels(rendered.labels.labels.begin(), rendered.labels.labels.end());
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = is_valid((**cloud)[i]) ? labels[i] : 0;
    // As the working memory segments: in the world frame, z up (the room's floor is larger than
    // the table; the up-vector and the height band keep the table the support).
    Cloud world = **cloud;
    const Pose& T = rendered.truth.T_world_camera;
    for (auto& p : world.points) {
      if (!is_valid(p)) continue;
      // The room's far walls are beyond a tabletop sensor's working range.
      if (p.z > kMaxRangeM) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
      else p.getVector3fMap() = (T * p.getVector3fMap().cast<double>()).cast<float>();
    }
    config.up = Eigen::Vector3d::UnitZ();
    Segmentation seg = segment(world, config, T.translation());
    std::vector<std::vector<int>> clusters;
    for (const auto& o : seg.objects) clusters.push_back(o.indices);
    const LabelScore score = score_against_labels(clusters, seg.planes.empty() ? std::vector<int>{} : seg.planes[0].indices,
                                                  labels, 1, 10, kMinVisiblePoints);
    ++run.frames;
    run.objects += score.objects.size();
    run.matched += score.matched();
    run.clusters += clusters.size();
    run.correct += score.correct_clusters();
    std::map<std::uint32_t, int> best;
    std::printf("  %s frame %2d: %zu clusters |", name.c_str(), f, clusters.size());
    for (const auto& o : score.objects) {
      best[o.object_id] = o.best_iou >= 0.5 ? o.best_cluster : -1;
      std::printf(" %u:%.2f", o.object_id, o.best_iou);
    }
    std::printf("\n");
    run.best.push_back(std::move(best));
    run.segmentations.push_back(std::move(seg));
  }
  std::printf("%s: %zu frames, objects matched %zu/%zu, clusters correct %zu/%zu\n", name.c_str(), run.frames, run.matched,
              run.objects, run.correct, run.clusters);
  return run;
}

// Every frame of a scenario, with the default config: each visible object is one cluster, and
// every cluster one object.
SceneRun expect_every_object_whole(const std::string& name, std::size_t frames) {
  const SceneRun run = run_scenario(name, 1, Config{});
  EXPECT_EQ(run.frames, frames) << name;
  EXPECT_EQ(run.matched, run.objects) << name;
  EXPECT_EQ(run.correct, run.clusters) << name;
  return run;
}

// Floors sit at what this method reached when they were set (docs/testing.md, "Simulator, exact labels"): the big
// stack comes apart in every frame; the small box on the 5 cm flat box is often merged with it
// (the flat box's front is less than three 2 cm patches high).
TEST(ScenarioSegmentation, StackedBoxesComeApartAndRestOnEachOther) {
  const SceneRun run = run_scenario("stacked");
  ASSERT_EQ(run.frames, 12u);
  EXPECT_GE(run.matched, 38u) << "of " << run.objects << " visible boxes";
  EXPECT_GE(run.correct, 38u) << "of " << run.clusters << " clusters";
  std::size_t big_stack = 0, supports = 0, supports_right = 0;
  for (std::size_t f = 0; f < run.frames; ++f) {
    const auto& best = run.best[f];
    const auto& objects = run.segmentations[f].objects;
    auto found = [&](std::uint32_t id) { return best.count(id) && best.at(id) >= 0; };
    big_stack += found(1) && found(2) ? 1 : 0;
    // Box 2 stands on box 1, box 4 on box 3; boxes 1 and 3 stand on the table.
    for (const auto& [upper, lower] : {std::pair{2u, 1u}, std::pair{4u, 3u}}) {
      if (!found(upper) || !found(lower)) continue;
      ++supports;
      supports_right += objects[best.at(upper)].supported_by == best.at(lower) && objects[best.at(lower)].supported_by == -1;
    }
  }
  std::printf("stacked: big stack apart in %zu/%zu frames, supports right %zu/%zu\n", big_stack, run.frames, supports_right, supports);
  EXPECT_EQ(big_stack, run.frames) << "the box on the big box is separate in every frame";
  EXPECT_EQ(supports_right, supports) << "a separated upper box rests on its lower box, which rests on the table";
}

// The cup against the box is merged with it in 5 of 12 frames, and the two blue boxes (same size
// and colour, the second turned by 6 degrees) are split in the wrong place in most.
TEST(ScenarioSegmentation, TouchingObjectsComeApart) {
  const SceneRun run = run_scenario("touching");
  ASSERT_EQ(run.frames, 12u);
  EXPECT_GE(run.matched, 28u) << "of " << run.objects << " visible objects";
  EXPECT_GE(run.correct, 28u) << "of " << run.clusters << " clusters";
  for (const auto& seg : run.segmentations)
    for (const auto& o : seg.objects) EXPECT_EQ(o.supported_by, -1) << "everything stands on the table";
}

// Twelve objects close together (the clutter scenario of the stream tests, every sixth of its 90
// frames): touching, occluded, a transparent glass (no depth: not counted), an open bowl and mug.
TEST(ScenarioSegmentation, Clutter) {
  const SceneRun run = run_scenario("clutter", 6);
  ASSERT_EQ(run.frames, 15u);
  // 148/151 and 154/175 when set (Euclidean clusters alone: 135/151 and 141/151); the wrong
  // clusters are pieces of the open mug and bowl and the mug merged with the box it touches.
  EXPECT_GE(run.matched, 148u) << "of " << run.objects << " visible objects";
  EXPECT_GE(run.correct, 154u) << "of " << run.clusters << " clusters";
}

// A box as wide as the table hides the table behind it: the table shows in two pieces, one
// support all the same, and the boxes on both pieces are found (with the largest piece alone
// as the support: 6 of 9, the box behind is lost).
TEST(ScenarioSegmentation, TableSplitByAnOccluderIsOneSupport) {
  const SceneRun run = expect_every_object_whole("hidden_table", 3);
  // Off, the largest visible piece alone is the support: measured 6 of 9.
  Config largest_piece;
  largest_piece.bridge_hidden_support = false;
  const SceneRun alone = run_scenario("hidden_table", 1, largest_piece);
  EXPECT_LT(alone.matched, run.matched);
}

// A box stands where a tall box hides the table, and no visible piece of the table reaches it:
// it stands on the table all the same (support_extent.h), and is found whole. Before the hidden
// feet widened the hull it was cut at the visible table's edge or lost.
TEST(ScenarioSegmentation, ABoxWhereTheTableIsHiddenStandsOnIt) { expect_every_object_whole("behind_pile", 3); }

// The demo's sample scene: a floor 3-3.6 m from the sensor lies in pieces behind the table, and
// its depth noise rises 2-13 cm above its plane there, within 3 sigma of the sensor's noise at that
// range. Such voxels are the floor, not objects hiding it: bridging stays off through them, and the
// scene keeps its 4 objects (it found 7 when they bridged: strips of floor noise at the far wall).
TEST(ScenarioSegmentation, FloorNoiseFarFromTheSensorBridgesNoSupport) {
  auto file = io::read_cloud(test::source_dir() / "sample_clouds/tabletop.pcd");
  ASSERT_TRUE(file.ok()) << file.error().message;
  Config largest_piece;
  largest_piece.bridge_hidden_support = false;
  const Segmentation plain = segment(*file->cloud, largest_piece, file->sensor_origin);
  const Segmentation seg = segment(*file->cloud, Config{}, file->sensor_origin);
  EXPECT_EQ(plain.objects.size(), 4u);
  ASSERT_EQ(seg.objects.size(), 4u);
  ASSERT_EQ(seg.planes.size(), plain.planes.size());
  for (std::size_t p = 0; p < seg.planes.size(); ++p) EXPECT_NEAR(seg.planes[p].area_m2, plain.planes[p].area_m2, 1e-9);
}

}  // namespace
}  // namespace scenewatch::segmentation
