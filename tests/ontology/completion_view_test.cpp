// Completion used by the expected view (issue 13: "the completed model ... used by the expected
// view when the object is seen from a new side"). The simulator shows a can from one side; the
// appearance memory keeps that view, the ontology describes the can from it and completes its
// primitive. Seen from the opposite side, the expected view from the mesh alone predicts the can's
// pixels with its front half (6.6 cm too far), the table or nothing (the memory's view looks the
// other way); with the completed surface splatted in
// (surprise::splat_surface), with its far side.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "scenewatch/background/appearance.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "scenewatch/surprise/expected_view.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

// A can (the size of cup_added's) alone on the table, a static camera on each side at about 0.8 m.
const char* kScenario = R"(name: far_side
seed: 3
objects:
  - {id: 2, name: can, shape: cylinder, radius_m: 0.033, height_m: 0.122, color: [210, 30, 30],
     texture: {type: stripes, color: [240, 240, 240], scale_m: 0.025}, position: [0.0, 0.0]}
phases:
  - name: front
    frames: 1
    camera: {type: static, position: [-0.7, 0.0, 1.2], target: [0.0, 0.0, 0.8]}
  - name: side
    frames: 1
    camera: {type: static, position: [0.0, -0.7, 1.2], target: [0.0, 0.0, 0.8]}
  - name: back
    frames: 1
    camera: {type: static, position: [0.7, 0.05, 1.2], target: [0.0, 0.0, 0.8]}
)";

constexpr std::uint16_t kCan = 2;  // its pixels are labelled 10 id .. 10 id + 9

bool is_can(std::uint16_t label) { return label / 10 == kCan; }

TEST(CompletionInTheExpectedView, TheFarSideOfACanIsPredicted) {
  test::TempDir dir("completion-view");
  std::ofstream(dir / "far_side.yaml") << kScenario;
  auto loaded = sim::load_scenario(dir / "far_side.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  auto simulator = sim::Simulator::create(sim::with_resolution(*loaded, 320, 240));
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  const Intrinsics K = simulator->scenario().intrinsics;

  // The front view: into the appearance memory, and the can's points (world frame) described.
  const sim::SimFrame front = simulator->render(0, 0);
  const Pose T_front = front.truth.T_world_camera_reported;
  background::AppearanceMemory memory;
  background::Keyframe keyframe;
  keyframe.color = front.color;
  keyframe.depth = front.depth;
  keyframe.T_world_camera = T_front;
  keyframe.intrinsics = K;
  ASSERT_TRUE(memory.add(keyframe).ok());
  auto cloud = io::rgbd_to_cloud(front.color, front.depth, K);
  ASSERT_TRUE(cloud.ok());
  std::vector<Eigen::Vector3d> can_world;
  Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
  for (std::size_t i = 0; i < (*cloud)->size(); ++i) {
    const PointT& p = (*cloud)->points[i];
    if (!is_valid(p) || !is_can(front.labels.labels[i])) continue;
    can_world.push_back(T_front * p.getVector3fMap().cast<double>());
    rgb += Eigen::Vector3f(p.r, p.g, p.b);
  }
  ASSERT_GE(can_world.size(), 500u);
  rgb /= static_cast<float>(can_world.size());
  auto classes = load_classes_file(test::source_dir() / "config/ontology.yaml");
  ASSERT_TRUE(classes.ok()) << classes.error().message;
  auto described = describe(can_world, Eigen::Vector3d::UnitZ(), *classes, T_front.translation());
  ASSERT_TRUE(described.ok()) << described.error().message;
  ASSERT_EQ(described->class_name, "can");
  ASSERT_FALSE(described->completed_points.empty());

  // Seen from the side (90 degrees on) and from the back: the share of the can's pixels whose
  // expected depth is within 1 cm of the depth observed there, from the mesh alone and with the
  // completed surface.
  // Measured: side 35.5 % -> 83.5 %, back 0.0 % -> 83.4 % (the rest: the splat's squares at the
  // silhouette and the top's rim, sensor noise beyond 1 cm).
  struct Case {
    std::size_t phase;
    double max_before, min_after;
  };
  for (const Case& c : {Case{1, 0.40, 0.80}, Case{2, 0.02, 0.80}}) {
    const std::size_t phase = c.phase;
    SCOPED_TRACE(simulator->scenario().phases[phase].name);
    const sim::SimFrame seen = simulator->render(phase, 0);
    surprise::ExpectedView view = surprise::render_expected_view(memory, seen.truth.T_world_camera_reported, K);
    const auto predicted = [&](const surprise::ExpectedView& v, std::size_t* coloured) {
      std::size_t pixels = 0, near = 0;
      *coloured = 0;
      for (std::size_t i = 0; i < v.pixel_count(); ++i) {
        const std::uint16_t observed_mm = seen.depth.depth_mm[i];
        if (!is_can(seen.labels.labels[i]) || observed_mm == 0) continue;
        ++pixels;
        if (v.depth_m[i] > 0 && std::abs(v.depth_m[i] - observed_mm * 0.001) <= 0.01) ++near;
        if (v.count[i] > 0) ++*coloured;
      }
      EXPECT_GT(pixels, 500u);
      return pixels ? static_cast<double>(near) / static_cast<double>(pixels) : 0.0;
    };
    std::size_t coloured_before = 0, coloured_after = 0;
    const double before = predicted(view, &coloured_before);
    surprise::KnownSurface completed;
    completed.points_world = described->completed_points;
    completed.spacing_m = DescribeConfig{}.completion_spacing_m;
    completed.rgb = rgb;
    const std::size_t changed = surprise::splat_surface(view, completed);
    const double after = predicted(view, &coloured_after);
    std::printf("can seen from the %s: %.1f %% of its pixels have an expected depth within 1 cm from the mesh alone, "
                "%.1f %% with the completed can (%zu pixels changed; %zu -> %zu of its pixels with a colour sample)\n",
                simulator->scenario().phases[phase].name.c_str(), 100 * before, 100 * after, changed, coloured_before,
                coloured_after);
    EXPECT_LT(before, c.max_before);
    EXPECT_GT(after, c.min_after);
  }
}

}  // namespace
}  // namespace scenewatch::ontology
