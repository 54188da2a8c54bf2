// The simulator end to end: determinism of the written bytes, ground truth against the pixels,
// round trips through io's readers, and glass that is seen in colour but not in depth.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/sequence_writer.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::sim {
namespace {

namespace fs = std::filesystem;

Scenario shipped(const std::string& name) {
  const fs::path path = name == "tabletop" ? test::source_dir() / "sample_clouds" / "tabletop.yaml"
                                           : test::source_dir() / "sample_clouds" / "scenarios" / (name + ".yaml");
  auto sc = load_scenario(path);
  if (!sc) throw std::runtime_error(sc.error().message);
  return std::move(*sc);
}

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Result<RunSummary> render_to(const Scenario& sc, const fs::path& dir) {
  auto sim = Simulator::create(sc);
  if (!sim) return sim.error();
  return sim->write(dir);
}

TEST(Simulator, SameSeedSameBytes) {
  const Scenario sc = with_frames(with_resolution(shipped("hand_picks_cup_upright"), 160, 120), 4);
  const fs::path a = test::make_temp_dir("sim-det-a"), b = test::make_temp_dir("sim-det-b"),
                 c = test::make_temp_dir("sim-det-c");
  ASSERT_TRUE(render_to(sc, a).ok());
  ASSERT_TRUE(render_to(sc, b).ok());
  Scenario other = sc;
  other.seed += 1;
  ASSERT_TRUE(render_to(other, c).ok());
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const std::string name = e.path().filename().string();
    ASSERT_TRUE(fs::exists(b / name)) << name;
    EXPECT_EQ(bytes(e.path()), bytes(b / name)) << name;
    ++files;
  }
  EXPECT_EQ(files, 4u * 4u + 3u);  // 4 files per frame + trajectory, intrinsics, ground truth
  // Another seed: other noise in colour and depth, the same labels and poses.
  EXPECT_NE(bytes(a / "frame-000001.color.png"), bytes(c / "frame-000001.color.png"));
  EXPECT_NE(bytes(a / "frame-000001.depth.png"), bytes(c / "frame-000001.depth.png"));
  EXPECT_EQ(bytes(a / "frame-000001.label.png"), bytes(c / "frame-000001.label.png"));
  EXPECT_EQ(bytes(a / "frame-000001.pose.txt"), bytes(c / "frame-000001.pose.txt"));
  for (const auto& d : {a, b, c}) fs::remove_all(d);
}

/// Back-projects every valid depth pixel with the ground-truth pose and checks that it lies on
/// the surface of the object its label names (signed distance of the object's primitive, an
/// independent description of the surface) within the sensor's noise model.
/// Objects are checked against the files alone (ground_truth.json); the table and the hand, which
/// the ground truth does not describe, against the simulator's scene.
void expect_depth_on_labelled_surfaces(const fs::path& dir, const Scenario& sc, const Simulator& sim) {
  auto seq = io::open_sequence(dir);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  auto truth = read_ground_truth(dir / "ground_truth.json");
  ASSERT_TRUE(truth.ok()) << truth.error().message;
  ASSERT_EQ(seq->frames.size(), truth->frames.size());
  const SensorModel sensor(sc.sensor, sc.seed);
  const Intrinsics& K = truth->intrinsics;
  std::map<std::uint16_t, const ObjectTruth*> by_label;
  for (const auto& o : truth->objects) by_label[o.label] = &o;
  std::size_t checked_objects = 0, checked_table = 0, checked_hand = 0;
  for (std::size_t f = 0; f < truth->frames.size(); ++f) {
    const FrameTruth& ft = truth->frames[f];
    auto depth = io::read_depth_png(seq->frames[f].depth);
    auto labels = io::read_label_png(dir / (ft.name + ".label.png"));
    ASSERT_TRUE(depth.ok() && labels.ok());
    const RenderScene scene = sim.render_scene(0, static_cast<int>(f));
    std::map<int, Pose> T_object_world;
    for (const auto& o : ft.objects) T_object_world[o.id] = o.T_world_object.inverse();
    for (int v = 0; v < K.height; ++v) {
      for (int u = 0; u < K.width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * K.width + u;
        const std::uint16_t mm = depth->depth_mm[i];
        if (mm == 0) continue;
        const double z = mm / 1000.0;
        const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
        const Eigen::Vector3d p_world = ft.T_world_camera * (z * ray);
        // Noise (3.9 sigma at most: the sampler's tails), quantization and mm rounding, along the ray.
        const double tol = (3.9 * sensor.depth_sigma_m(z) + sensor.quantization_step_m(z, K.fx) + 0.0006) * ray.norm();
        const std::uint16_t label = labels->labels[i];
        if (label >= kObjectLabelFactor) {
          const ObjectTruth* o = by_label.at(label);
          const double d = signed_distance(o->shape, T_object_world.at(o->id) * p_world);
          ASSERT_LE(std::abs(d), tol) << ft.name << " pixel (" << u << ", " << v << ") label " << label;
          ++checked_objects;
        } else if (label == kLabelTable || label == kLabelHand) {
          double nearest = 1e9;
          for (const RenderItem& item : scene.items) {
            if (item.label != label) continue;
            nearest = std::min(nearest, std::abs(signed_distance(item.shape, item.T_world_item.inverse() * p_world)));
          }
          ASSERT_LE(nearest, tol) << ft.name << " pixel (" << u << ", " << v << ") label " << label;
          ++(label == kLabelTable ? checked_table : checked_hand);
        }
      }
    }
  }
  EXPECT_GT(checked_objects, 200u);
  EXPECT_GT(checked_table, 200u);
  if (!sc.phases[0].hand.keys.empty()) {
    EXPECT_GT(checked_hand, 20u);
  }
}

TEST(Simulator, DepthLiesOnTheLabelledSurfaces) {
  for (const char* name : {"clutter", "hand_picks_cup_upright"}) {
    const Scenario sc = with_frames(with_resolution(shipped(name), 320, 240), 3);
    const fs::path dir = test::make_temp_dir("sim-gt-pixels");
    auto sim = Simulator::create(sc);
    ASSERT_TRUE(sim.ok()) << sim.error().message;
    auto run = sim->write(dir);
    ASSERT_TRUE(run.ok()) << run.error().message;
    expect_depth_on_labelled_surfaces(dir, sc, *sim);
    fs::remove_all(dir);
  }
}

TEST(Simulator, HandIsLabelledWhileItIsInView) {
  Scenario sc = with_resolution(shipped("hand_picks_cup_upright"), 160, 120);
  auto sim = Simulator::create(sc);
  ASSERT_TRUE(sim.ok());
  const SimFrame f = sim->render(0, 60);  // carrying the cup
  std::map<std::uint16_t, int> count;
  for (auto l : f.labels.labels) ++count[l];
  EXPECT_GT(count[kLabelHand], 50);
  EXPECT_GT(count[30], 30);
  EXPECT_GT(count[kLabelTable], 1000);
  ASSERT_EQ(f.truth.held, std::vector<int>{3});
}

TEST(Simulator, TrajectoryPosesAndIntrinsicsRoundTripThroughIo) {
  Scenario sc = with_frames(with_resolution(shipped("object_moved"), 160, 120), 3);
  sc.sensor.pose_sigma_m = 0.01;  // the written poses are the noisy ones, the true ones are in the JSON
  sc.sensor.pose_sigma_deg = 0.5;
  auto sim = Simulator::create(sc);
  ASSERT_TRUE(sim.ok());
  const fs::path dir = test::make_temp_dir("sim-roundtrip");
  auto run = sim->write(dir);
  ASSERT_TRUE(run.ok()) << run.error().message;
  ASSERT_EQ(run->sequence_dirs.size(), 2u);
  EXPECT_EQ(run->sequence_dirs[0], dir / "before");
  EXPECT_TRUE(fs::exists(dir / "changes.json"));
  for (std::size_t p = 0; p < 2; ++p) {
    const fs::path seq_dir = run->sequence_dirs[p];
    EXPECT_TRUE(io::is_sequence_dir(seq_dir));
    auto seq = io::open_sequence(seq_dir);
    ASSERT_TRUE(seq.ok()) << seq.error().message;
    EXPECT_NEAR(seq->intrinsics.fx, sc.intrinsics.fx, 1e-6);
    EXPECT_NEAR(seq->intrinsics.cx, sc.intrinsics.cx, 1e-6);
    auto tum = io::read_tum(seq_dir / "trajectory.txt");
    ASSERT_TRUE(tum.ok()) << tum.error().message;
    auto truth = read_ground_truth(seq_dir / "ground_truth.json");
    ASSERT_TRUE(truth.ok()) << truth.error().message;
    ASSERT_EQ(tum->size(), 3u);
    ASSERT_EQ(seq->frames.size(), 3u);
    for (int f = 0; f < 3; ++f) {
      const FrameTruth expected = sim->frame_truth(p, f);
      const auto fi = static_cast<std::size_t>(f);
      EXPECT_TRUE((*tum)[fi].T_world_camera.isApprox(expected.T_world_camera_reported, 1e-6));
      EXPECT_NEAR((*tum)[fi].stamp_s, expected.stamp_s, 1e-6);
      ASSERT_TRUE(seq->frames[fi].T_world_camera.has_value());
      EXPECT_TRUE(seq->frames[fi].T_world_camera->isApprox(expected.T_world_camera_reported, 1e-6));
      auto pose_file = io::read_pose_matrix(seq_dir / (frame_name(f) + ".pose.txt"));
      ASSERT_TRUE(pose_file.ok());
      EXPECT_TRUE(pose_file->isApprox(expected.T_world_camera_reported, 1e-6));
      // Noisy reported pose, exact true pose in the ground truth.
      EXPECT_FALSE(expected.T_world_camera_reported.isApprox(expected.T_world_camera, 1e-6));
      EXPECT_TRUE(truth->frames[fi].T_world_camera.isApprox(expected.T_world_camera, 1e-12));
      for (std::size_t o = 0; o < expected.objects.size(); ++o) {
        EXPECT_TRUE(truth->frames[fi].objects[o].T_world_object.isApprox(expected.objects[o].T_world_object, 1e-12));
      }
    }
    // The CLI's loader takes a simulated frame as it is.
    auto frame = io::load_sequence_frame(*seq, 1);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    ASSERT_TRUE(frame->intrinsics.has_value());
    EXPECT_EQ(frame->intrinsics->width, 160);
    EXPECT_EQ(frame->intrinsics->height, 120);
    EXPECT_EQ(frame->cloud->width, 160u);
    EXPECT_EQ(frame->cloud->height, 120u);
    EXPECT_GT(count_valid(*frame->cloud), 160u * 120u / 2);
  }
  auto changes = read_changes(dir / "changes.json");
  ASSERT_TRUE(changes.ok()) << changes.error().message;
  ASSERT_EQ(changes->size(), 1u);
  ASSERT_EQ((*changes)[0].moved.size(), 1u);
  EXPECT_EQ((*changes)[0].moved[0].id, 2);
  fs::remove_all(dir);
}

TEST(Simulator, TransparentGlassHasColourButNoDepth) {
  const char* yaml = R"(
name: glass
seed: 3
intrinsics: {width: 160, height: 120}
objects:
  - {id: 1, name: glass, shape: frustum, radius_m: 0.03, top_radius_m: 0.037, height_m: 0.13, open_top: true,
     wall_m: 0.003, color: [200, 225, 235], transparent: true, opacity: 0.3, position: [0, 0]}
frames: 1
camera: {type: static, position: [-0.6, 0, 1.1], target: [0, 0, 0.8]}
)";
  auto sc = parse_scenario(yaml);
  ASSERT_TRUE(sc.ok()) << sc.error().message;
  Scenario without = *sc;
  without.objects.clear();
  auto with_glass = Simulator::create(*sc);
  auto no_glass = Simulator::create(without);
  ASSERT_TRUE(with_glass.ok() && no_glass.ok());
  const SimFrame a = with_glass->render(0, 0);
  const SimFrame b = no_glass->render(0, 0);
  int glass_pixels = 0, glass_depth = 0;
  double colour_difference = 0;
  for (std::size_t i = 0; i < a.labels.labels.size(); ++i) {
    if (a.labels.labels[i] != 10) continue;
    ++glass_pixels;
    glass_depth += a.depth.depth_mm[i] != 0;
    for (int c = 0; c < 3; ++c) colour_difference += std::abs(a.color.rgb[3 * i + c] - b.color.rgb[3 * i + c]);
  }
  ASSERT_GT(glass_pixels, 100);
  EXPECT_EQ(glass_depth, 0);                                  // no valid depth on the glass
  EXPECT_GT(colour_difference / (3.0 * glass_pixels), 10.0);  // but it is visible in colour

  // Configured to return the surface behind it, the glass pixels get the background's depth.
  sc->sensor.transparent_depth = TransparentDepth::kBehind;
  sc->sensor.noise = false;
  without.sensor = sc->sensor;
  auto behind = Simulator::create(*sc);
  auto behind_bg = Simulator::create(without);
  const SimFrame c = behind->render(0, 0);
  const SimFrame d = behind_bg->render(0, 0);
  for (std::size_t i = 0; i < c.labels.labels.size(); ++i) {
    if (c.labels.labels[i] == 10) {
      ASSERT_EQ(c.depth.depth_mm[i], d.depth.depth_mm[i]);
    }
  }
}

TEST(Simulator, CommittedDemoSampleIsCurrent) {
  // sample_clouds/tabletop/ and tabletop.pcd are rendered from tabletop.yaml; when the renderer
  // changes on purpose, regenerate them (sample_clouds/README.md).
  const fs::path dir = test::source_dir() / "sample_clouds" / "tabletop";
  auto seq = io::open_sequence(dir);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  ASSERT_EQ(seq->frames.size(), 1u);
  auto sim = Simulator::create(shipped("tabletop"));
  ASSERT_TRUE(sim.ok());
  const SimFrame f = sim->render(0, 0);
  auto color = io::read_color_png(seq->frames[0].color);
  auto depth = io::read_depth_png(seq->frames[0].depth);
  auto labels = io::read_label_png(dir / "frame-000000.label.png");
  ASSERT_TRUE(color.ok() && depth.ok() && labels.ok());
  EXPECT_EQ(color->rgb, f.color.rgb);
  EXPECT_EQ(depth->depth_mm, f.depth.depth_mm);
  EXPECT_EQ(labels->labels, f.labels.labels);
  auto cloud = io::read_cloud(test::source_dir() / "sample_clouds" / "tabletop.pcd");
  ASSERT_TRUE(cloud.ok()) << cloud.error().message;
  EXPECT_TRUE(cloud->organized);
  EXPECT_EQ(cloud->cloud->width, static_cast<std::uint32_t>(f.depth.width));
  std::size_t valid_depth = 0;
  for (auto mm : f.depth.depth_mm) valid_depth += mm != 0;
  EXPECT_EQ(cloud->valid_points, valid_depth);
}

TEST(Simulator, RejectsBadHandScripts) {
  Scenario sc = shipped("hand_picks_cup_upright");
  sc.phases[0].hand.keys[6].release_id = 1;  // releases an object it does not hold
  auto sim = Simulator::create(sc);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message.find("hand.keys[6].release"), std::string::npos) << sim.error().message;
}

}  // namespace
}  // namespace scenewatch::sim
