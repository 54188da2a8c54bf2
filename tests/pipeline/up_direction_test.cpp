// The world's up without a configured one: hrt1's camera looks down at a table in front of a wall
// whose plane is larger (1.0-1.5 m2 against the table's 1.4 m2). The pose's world is the robot's
// base, z up, so the right answer is known on every frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/config_loader.h"
#include "scenewatch/pipeline/working_memory.h"
#include "shipped_config.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

// Also the object list: what stands on the wall (the relief of a whiteboard, posters) is not an
// object. Two objects stand on the table (a bin and a toy). The most listed in any frame from the
// fifth on, and at the end, measured: pick_toy_1 2 and 2 (the bin and the toy, in every frame),
// pick_toy_2 4 and 3. Before the body was taken to go on downward (stop 56: the person's trousers
// and hips at the table's edge, below the shirt the detector found): 5 and 3. Before what crosses
// the table's height was left out (stop 54): 5 and 4, 7
// and 5 (the chair beside the table; its back and seat stand inside the table's hull, which bands
// of the wall and the chair at the table's height stretch); before the person's body and pieces of
// listed objects were: 6 and 6, 8 and 8; 7 and 10 while a cluster seen in one frame was listed,
// tracking.confirm_frames 1; at the end 18 and 25-26 before strips narrower than the sensor
// resolves, pieces seen in place without a cluster of their own and pieces of hands were dropped;
// 41 and 60 when the wall's pieces were listed. What remains in pick_toy_2: pieces behind the
// person, 110-480 points 1.7-1.8 m out (frames 0-13, 17-18, 29-31), by the bin (frames 35-36) and
// by the hand (from frame 40); from the fifth frame on 2 listed in 19 frames, 3 in 16, 4 in 3 (replay).
void expect_table_up_on_every_frame(const std::string& name, std::size_t max_objects, std::size_t max_at_end) {
  const std::optional<Config> shipped = test::shipped_pipeline_config();
  ASSERT_TRUE(shipped);
  const Config& config = *shipped;
  ASSERT_FALSE(config.segmentation.up) << "the shipped config sets no up: the test is about finding it";
  auto seq = io::open_sequence(test::data_dir() / "hrt1" / name);
  ASSERT_TRUE(seq) << seq.error().message;
  WorkingMemory memory(config);
  int wall_frames = 0;
  double worst_deg = 0;
  std::size_t on_wall = 0;  // sightings of listed objects whose support faces sideways
  std::size_t most_listed = 0;  // from the fifth frame on
  for (std::size_t i = 0; i < seq->frames.size(); ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    ASSERT_TRUE(frame) << frame.error().message;
    ASSERT_TRUE(memory.process(*frame));
    const auto snapshot = memory.snapshot();
    if (i >= 4) most_listed = std::max(most_listed, snapshot->objects.size());
    for (const auto& o : snapshot->objects) {
      if (o.foreground || o.last_seen_s != frame->stamp_s) continue;
      for (const auto& p : snapshot->planes)
        if (p.id == o.cluster.plane_id && std::abs(p.normal.z()) < std::cos(M_PI / 4)) ++on_wall;
    }
    if (snapshot->planes.empty()) continue;
    const double deg = std::acos(std::clamp(snapshot->up_world.z(), -1.0, 1.0)) * 180.0 / M_PI;
    worst_deg = std::max(worst_deg, deg);
    wall_frames += deg > 45 ? 1 : 0;
  }
  const std::size_t listed = memory.snapshot()->objects.size();
  std::printf("%s: up within %.1f deg of the base's z on every frame with planes; %d frames took the wall; "
              "%zu objects listed at the end, at most %zu in a frame from the fifth on, %zu sightings of objects on the wall\n",
              name.c_str(), worst_deg, wall_frames, listed, most_listed, on_wall);
  EXPECT_EQ(on_wall, 0u);
  EXPECT_LE(most_listed, max_objects);
  EXPECT_LE(listed, max_at_end);
  EXPECT_EQ(wall_frames, 0);
  // The table's fitted normal: within 0.4 degrees of the base's z on every frame of both (3.0
  // degrees on pick_toy_1's frame 35 when it was first measured, with every pixel segmented).
  EXPECT_LT(worst_deg, 4.0);
}

TEST(UpDirection, IsTheTablesNotTheLargerWallsOnHrt1PickToy1AndNothingStandsOnTheWall) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_1");
  expect_table_up_on_every_frame("pick_toy_1", 2, 2);
}

TEST(UpDirection, IsTheTablesNotTheLargerWallsOnHrt1PickToy2AndNothingStandsOnTheWall) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_2");
  expect_table_up_on_every_frame("pick_toy_2", 4, 3);
}

}  // namespace
}  // namespace scenewatch::pipeline
