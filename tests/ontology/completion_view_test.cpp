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
#include <memory>
#include <optional>

#include "scenewatch/background/appearance.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "scenewatch/surprise/expected_view.h"
#include "scenewatch/surprise/surprise_map.h"
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

// The scene seen from the front: that view in the appearance memory, and the can as the
// segmentation gives it (world points, mean colour, colour covariance), described.
struct FrontView {
  std::optional<sim::Simulator> simulator;
  Intrinsics K;
  background::AppearanceMemory memory;
  std::vector<Eigen::Vector3d> can_world;
  Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
  Eigen::Matrix3f rgb_covariance = Eigen::Matrix3f::Zero();
  std::optional<ObjectDescription> described;
};

// Fails the calling test (gtest's EXPECTs) and returns a view without a description on error.
std::unique_ptr<FrontView> see_front(const std::string& scenario) {
  auto out = std::make_unique<FrontView>();
  test::TempDir dir("completion-view");
  std::ofstream(dir / "far_side.yaml") << scenario;
  auto loaded = sim::load_scenario(dir / "far_side.yaml");
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
  if (!loaded.ok()) return out;
  auto simulator = sim::Simulator::create(sim::with_resolution(*loaded, 320, 240));
  EXPECT_TRUE(simulator.ok()) << simulator.error().message;
  if (!simulator.ok()) return out;
  out->simulator.emplace(std::move(*simulator));
  out->K = out->simulator->scenario().intrinsics;
  const sim::SimFrame front = out->simulator->render(0, 0);
  const Pose T_front = front.truth.T_world_camera_reported;
  background::Keyframe keyframe;
  keyframe.color = front.color;
  keyframe.depth = front.depth;
  keyframe.T_world_camera = T_front;
  keyframe.intrinsics = out->K;
  EXPECT_TRUE(out->memory.add(keyframe).ok());
  auto cloud = io::rgbd_to_cloud(front.color, front.depth, out->K);
  EXPECT_TRUE(cloud.ok());
  if (!cloud.ok()) return out;
  std::vector<Eigen::Vector3f> colours;
  for (std::size_t i = 0; i < (*cloud)->size(); ++i) {
    const PointT& p = (*cloud)->points[i];
    if (!is_valid(p) || !is_can(front.labels.labels[i])) continue;
    out->can_world.push_back(T_front * p.getVector3fMap().cast<double>());
    colours.emplace_back(p.r, p.g, p.b);
  }
  EXPECT_GE(colours.size(), 500u);
  if (colours.empty()) return out;
  for (const auto& c : colours) out->rgb += c;
  out->rgb /= static_cast<float>(colours.size());
  for (const auto& c : colours) out->rgb_covariance += (c - out->rgb) * (c - out->rgb).transpose();
  out->rgb_covariance /= static_cast<float>(colours.size());
  auto classes = load_classes_file(test::source_dir() / "config/ontology.yaml");
  EXPECT_TRUE(classes.ok()) << classes.error().message;
  if (!classes.ok()) return out;
  auto described = describe(out->can_world, Eigen::Vector3d::UnitZ(), *classes, T_front.translation());
  EXPECT_TRUE(described.ok()) << described.error().message;
  if (!described.ok()) return out;
  EXPECT_EQ(described->class_name, "can");
  EXPECT_FALSE(described->completed_points.empty());
  out->described = std::move(*described);
  return out;
}

// The completed can as a known surface, with or without its colours' spread.
surprise::KnownSurface completed_can(const FrontView& front, bool with_spread) {
  surprise::KnownSurface completed;
  completed.points_world = front.described->completed_points;
  completed.spacing_m = DescribeConfig{}.completion_spacing_m;
  completed.rgb = front.rgb;
  if (with_spread) completed.rgb_covariance = front.rgb_covariance;
  return completed;
}

TEST(CompletionInTheExpectedView, TheFarSideOfACanIsPredicted) {
  const auto front = see_front(kScenario);
  ASSERT_TRUE(front->described);
  sim::Simulator* simulator = &*front->simulator;
  const Intrinsics K = front->K;

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
    surprise::ExpectedView view = surprise::render_expected_view(front->memory, seen.truth.T_world_camera_reported, K);
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
    const std::size_t changed = surprise::splat_surface(view, completed_can(*front, false));
    const double after = predicted(view, &coloured_after);
    std::printf("can seen from the %s: %.1f %% of its pixels have an expected depth within 1 cm from the mesh alone, "
                "%.1f %% with the completed can (%zu pixels changed; %zu -> %zu of its pixels with a colour sample)\n",
                simulator->scenario().phases[phase].name.c_str(), 100 * before, 100 * after, changed, coloured_before,
                coloured_after);
    EXPECT_LT(before, c.max_before);
    EXPECT_GT(after, c.min_after);
  }
}

// What the completion changes for the planner: the image surprise of a can seen from its far
// side, with the pipeline's surprise settings (robust comparison, regions), from the mesh alone
// and with the completed can splatted in with the seen side's colours.
struct FarSide {
  std::size_t can = 0, known = 0, in_region = 0;  ///< the can's pixels: all, with a surprise, in regions
  double mean_kl = 0;
  std::size_t painted_in_region = 0;  ///< the same with the can painted blue
  double painted_mean_kl = 0;
};

void print(const char* what, const FarSide& s) {
  std::printf("%s: %zu of its %zu pixels with a known surprise, %zu in surprise regions (mean KL %.1f nats); "
              "painted blue: %zu in surprise regions (mean KL %.1f nats)\n",
              what, s.known, s.can, s.in_region, s.mean_kl, s.painted_in_region, s.painted_mean_kl);
}

enum class Prediction { kMeshAlone, kMeanColour, kMeanColourAndSpread };

// `scenario`: kScenario's can, or the same can without its stripes.
FarSide far_side_surprise(const std::string& scenario, Prediction prediction) {
  FarSide s;
  const auto front = see_front(scenario);
  if (!front->described) return s;
  sim::Simulator* simulator = &*front->simulator;
  const Intrinsics K = front->K;
  const sim::SimFrame back = simulator->render(2, 0);
  const surprise::SurpriseConfig config;  // the pipeline's defaults
  const surprise::SurpriseKernel kernel(config.prior, config.min_samples);
  surprise::ExpectedView view = surprise::render_expected_view(front->memory, back.truth.T_world_camera_reported, K, config.view);
  if (prediction != Prediction::kMeshAlone)
    surprise::splat_surface(view, completed_can(*front, prediction == Prediction::kMeanColourAndSpread),
                            config.view.depth_tolerance_m);
  // The can's pixels in surprise regions, of an observation.
  const auto in_regions = [&](const ColorImage& observed, std::size_t* known, double* mean_kl) {
    auto map = surprise::compute_surprise(view, observed, kernel, &config.robust);
    EXPECT_TRUE(map.ok());
    if (!map.ok()) return std::size_t{0};
    std::vector<char> in_region(view.pixel_count(), 0);
    for (const auto& region : surprise::find_regions(*map, view, &back.depth, config.regions))
      for (std::uint32_t i : region.pixels) in_region[i] = 1;
    std::size_t n = 0;
    for (std::size_t i = 0; i < view.pixel_count(); ++i) {
      if (!is_can(back.labels.labels[i])) continue;
      n += in_region[i] ? 1 : 0;
      if (!std::isnan(map->total[i])) {
        ++*known;
        *mean_kl += map->total[i];
      }
    }
    return n;
  };
  for (std::size_t i = 0; i < back.labels.labels.size(); ++i) s.can += is_can(back.labels.labels[i]) ? 1 : 0;
  s.in_region = in_regions(back.color, &s.known, &s.mean_kl);
  if (s.known) s.mean_kl /= static_cast<double>(s.known);
  // The same back with the can painted blue (its red and blue swapped): a real change of colour.
  ColorImage painted = back.color;
  for (std::size_t i = 0; i < back.labels.labels.size(); ++i)
    if (is_can(back.labels.labels[i])) std::swap(painted.rgb[3 * i], painted.rgb[3 * i + 2]);
  std::size_t painted_known = 0;
  s.painted_in_region = in_regions(painted, &painted_known, &s.painted_mean_kl);
  if (painted_known) s.painted_mean_kl /= static_cast<double>(painted_known);
  return s;
}

std::string without_stripes(std::string scenario) {
  const std::string stripes = ",\n     texture: {type: stripes, color: [240, 240, 240], scale_m: 0.025}";
  const auto at = scenario.find(stripes);
  if (at != std::string::npos) scenario.erase(at, stripes.size());
  return scenario;
}

// Measured: the mesh alone predicts none of the back's 938 pixels (the memory's one view looks at
// the other side), so nothing there can surprise. Completed with its mean colour alone, the
// striped can's back is all surprise (938 of 938 pixels in regions, mean KL 32.9 nats): its white
// stripes are far from a red-pink mean. With the seen side's colour spread, none is (mean KL 0.3;
// the plain can 0.2). The spread is as wide as the object's colours and shading, so a new colour
// on a side never seen is weaker evidence than on a side seen: the plain red can painted blue
// reads 6.1 nats per pixel, 30 times its true back but below the 12 that starts a region
// (seven samples' Gamma posterior; the striped can painted blue: 2.1).
TEST(CompletionInTheExpectedView, TheFarSideOfAKnownCanIsPredictedInColour) {
  const FarSide mesh = far_side_surprise(kScenario, Prediction::kMeshAlone);
  const FarSide mean = far_side_surprise(kScenario, Prediction::kMeanColour);
  const FarSide striped = far_side_surprise(kScenario, Prediction::kMeanColourAndSpread);
  const FarSide plain = far_side_surprise(without_stripes(kScenario), Prediction::kMeanColourAndSpread);
  print("striped can from the back, mesh alone", mesh);
  print("striped can from the back, completed with its mean colour", mean);
  print("striped can from the back, completed with its colours' spread", striped);
  print("plain can from the back, completed with its colours' spread", plain);
  ASSERT_GT(mesh.can, 500u);
  ASSERT_GT(plain.can, 500u);
  EXPECT_EQ(mesh.known, 0u);
  EXPECT_GT(mean.in_region, 0.9 * static_cast<double>(mean.can));
  for (const FarSide* s : {&striped, &plain}) {
    EXPECT_GT(s->known, 0.95 * static_cast<double>(s->can));  // predicted
    EXPECT_LT(s->in_region, 0.05 * static_cast<double>(s->can));  // and not a surprise
  }
  EXPECT_LT(striped.mean_kl, 0.5);
  EXPECT_LT(plain.mean_kl, 0.5);
  EXPECT_GT(plain.painted_mean_kl, 5.0);  // the evidence of a new colour is still there
}

}  // namespace
}  // namespace scenewatch::ontology
