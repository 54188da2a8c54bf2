// The TUM RGB-D benchmark layout against the layout the simulator writes: the same recording in
// both must give the same map, objects and events. The converter below writes what TUM publishes:
// rgb/ and depth/ PNGs named by their time, rgb.txt and depth.txt with colour and depth stamps
// jittered apart (as two sensors' clocks are), depth in units of 1/5000 m, and groundtruth.txt at
// about twice the frame rate (each frame's pose near its depth stamp, a decoy pose in between).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>

#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {
namespace fs = std::filesystem;

std::string stamped(const std::string& folder, double t) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%s/%.6f.png", folder.c_str(), t);
  return buffer;
}

/// Writes the frames-layout sequence `from` as a TUM RGB-D folder `to`, its clock starting at
/// start_s. One extra colour image, 0.5 s after the last, has no depth (it must be skipped).
void to_tum_layout(const fs::path& from, const fs::path& to, double start_s, std::mt19937& rng) {
  auto seq = io::open_sequence(from);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  fs::create_directories(to / "rgb");
  fs::create_directories(to / "depth");
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  std::vector<io::StampedFile> rgb, depth;
  std::vector<io::StampedPose> truth;
  double t = start_s;
  for (const auto& frame : seq->frames) {
    t = start_s + static_cast<double>(rgb.size()) / 30.0;
    const double t_rgb = t + jitter(rng), t_depth = t + jitter(rng);
    rgb.push_back({t_rgb, stamped("rgb", t_rgb), 0});
    depth.push_back({t_depth, stamped("depth", t_depth), 0});
    fs::copy_file(frame.color, to / rgb.back().file);
    auto mm = io::read_depth_png(frame.depth);
    ASSERT_TRUE(mm.ok()) << mm.error().message;
    for (auto& d : mm->depth_mm) {
      ASSERT_LE(d, 65535 / 5) << frame.depth;
      d = static_cast<std::uint16_t>(d * 5);  // millimetres to 1/5000 m
    }
    ASSERT_TRUE(io::write_depth_png(to / depth.back().file, *mm).ok());
    ASSERT_TRUE(frame.T_world_camera.has_value());
    truth.push_back({t_depth + jitter(rng), *frame.T_world_camera});
    // Half way to the next frame: a pose 5 cm off, which a wrong association would use.
    truth.push_back({t + 1.0 / 60.0, Eigen::Translation3d(0.05, 0, 0) * *frame.T_world_camera});
  }
  rgb.push_back({t + 0.5, stamped("rgb", t + 0.5), 0});
  fs::copy_file(seq->frames.back().color, to / rgb.back().file);
  std::shuffle(truth.begin(), truth.end(), rng);  // the reader sorts by time
  ASSERT_TRUE(io::write_tum_list(to / "rgb.txt", rgb).ok());
  ASSERT_TRUE(io::write_tum_list(to / "depth.txt", depth).ok());
  ASSERT_TRUE(io::write_tum(to / "groundtruth.txt", truth).ok());
  fs::copy_file(from / "camera-intrinsics.txt", to / "camera-intrinsics.txt");  // not TUM's default camera
}

struct Outcome {
  std::vector<Event> events;
  Stats stats;
  background::BoxOccupancy scene;
  std::vector<TrackedObject> objects;
  std::string map_bytes;  ///< the saved OctoMap
};

Outcome replay(const std::vector<fs::path>& dirs, const fs::path& model_dir) {
  Outcome out;
  Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  WorkingMemory memory(config);
  for (const auto& dir : dirs) {
    auto seq = io::open_sequence(dir);
    EXPECT_TRUE(seq.ok()) << seq.error().message;
    if (!seq.ok()) return out;
    for (std::size_t i = 0; i < seq->frames.size(); ++i) {
      auto frame = io::load_sequence_frame(*seq, i);
      EXPECT_TRUE(frame.ok()) << frame.error().message;
      if (!frame.ok()) return out;
      auto result = memory.process(*frame);
      EXPECT_TRUE(result.ok()) << result.error().message;
      if (!result.ok()) return out;
      out.events.insert(out.events.end(), result->events.begin(), result->events.end());
    }
  }
  out.stats = memory.stats();
  out.scene = memory.query_box(Aabb{Eigen::Vector3d(-1.5, -1.5, -0.1), Eigen::Vector3d(1.5, 1.5, 2.0)});
  out.objects = memory.snapshot()->objects;
  EXPECT_TRUE(memory.save(model_dir).ok());
  std::ifstream in(model_dir / "current" / "background.ot", std::ios::binary);
  out.map_bytes.assign(std::istreambuf_iterator<char>(in), {});
  return out;
}

TEST(TumLayout, SimulatedRecordingGivesTheSameMapAndEventsAsTheOriginal) {
  test::TempDir tmp("tum");
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/cup_added.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  auto simulator = sim::Simulator::create(sim::with_frames(sim::with_resolution(*loaded, 320, 240), 12));
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  auto written = simulator->write(tmp / "original");
  ASSERT_TRUE(written.ok()) << written.error().message;
  ASSERT_EQ(written->sequence_dirs.size(), 2u);

  std::mt19937 rng(7);
  std::vector<fs::path> tum_dirs;
  double start_s = 1305031102.0;  // TUM stamps are Unix times
  for (const auto& dir : written->sequence_dirs) {
    tum_dirs.push_back(tmp / "tum" / dir.filename());
    ASSERT_NO_FATAL_FAILURE(to_tum_layout(dir, tum_dirs.back(), start_s, rng));
    start_s += 10.0;
    auto seq = io::open_sequence(tum_dirs.back());
    ASSERT_TRUE(seq.ok()) << seq.error().message;
    EXPECT_EQ(seq->layout, io::SequenceLayout::kTum);
    EXPECT_EQ(seq->frames.size(), 12u);
    EXPECT_EQ(seq->skipped_without_depth, 1u) << "the extra colour image";
    EXPECT_EQ(seq->skipped_without_pose, 0u);
  }

  const Outcome original = replay(written->sequence_dirs, tmp / "model-original");
  const Outcome tum = replay(tum_dirs, tmp / "model-tum");
  ASSERT_EQ(original.events.size(), 1u) << "the cup, added";
  EXPECT_EQ(original.events[0].kind, EventKind::kObjectAdded);
  ASSERT_EQ(tum.events.size(), original.events.size());
  for (std::size_t k = 0; k < tum.events.size(); ++k) {
    EXPECT_EQ(tum.events[k].kind, original.events[k].kind);
    EXPECT_LT((tum.events[k].centroid_world - original.events[k].centroid_world).norm(), 1e-4);
    EXPECT_LT((tum.events[k].box_world.min - original.events[k].box_world.min).norm(), 1e-4);
    EXPECT_LT((tum.events[k].box_world.max - original.events[k].box_world.max).norm(), 1e-4);
    EXPECT_NEAR(tum.events[k].score, original.events[k].score, 1e-4);
  }
  EXPECT_EQ(tum.stats.points_processed, original.stats.points_processed);
  EXPECT_EQ(tum.stats.map_leaf_nodes, original.stats.map_leaf_nodes);
  EXPECT_EQ(tum.stats.map_occupied_leaves, original.stats.map_occupied_leaves);
  EXPECT_EQ(tum.scene.occupied_voxels, original.scene.occupied_voxels);
  EXPECT_EQ(tum.scene.free_voxels, original.scene.free_voxels);
  ASSERT_FALSE(original.map_bytes.empty());
  EXPECT_TRUE(tum.map_bytes == original.map_bytes) << "the saved OctoMaps differ";
  ASSERT_EQ(tum.objects.size(), original.objects.size());
  EXPECT_GE(original.objects.size(), 4u) << "box, can, ball and the cup (the can's lid may be listed apart)";
  for (std::size_t k = 0; k < tum.objects.size(); ++k) {
    EXPECT_LT((tum.objects[k].cluster.centroid - original.objects[k].cluster.centroid).norm(), 1e-4);
  }
}

}  // namespace
}  // namespace scenewatch::pipeline
