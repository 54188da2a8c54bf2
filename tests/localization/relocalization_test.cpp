// Relocalization and homing (issue 29 items 3-4) on the real 7-Scenes kitchen: keyframes of files
// 0-248, frames of files 250-498 placed without a prior, against the recording's poses; the
// RANSAC against an exact oracle; the keyframe feature file.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "kitchen_data.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/localization/keyframe_features.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/localization/pose_error.h"
#include "scenewatch/localization/relocalizer.h"
#include "scenewatch/localization/rigid_ransac.h"
#include "scenewatch/pipeline/working_memory.h"
#include "test_data.h"

namespace scenewatch::localization {
namespace {

using test_kitchen::kHeldOutEnd;
using test_kitchen::kitchen;
using test_kitchen::kModelFrames;
using test_kitchen::load;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

bool within_5cm_5deg(const background::ViewDistance& e) { return e.translation_m <= 0.05 && e.rotation_deg <= 5.0; }

// The appearance memory's keyframes of the model half, at the recording's poses.
background::AppearanceMemory model_half(const io::Sequence& seq) {
  background::AppearanceMemory memory;
  for (std::size_t i = 0; i < kModelFrames; ++i) {
    auto kf = background::keyframe_from_frame(load(seq, i));
    EXPECT_TRUE(kf.ok());
    EXPECT_TRUE(memory.consider(std::move(*kf)).ok());
  }
  return memory;
}

// 35 degrees about the world's z axis and 1.4 m along x: another run's odometry frame.
Pose odometry_offset() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(35.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.4, 0.0, 0.0);
  return T;
}

TEST(RigidRansac, RecoversAKnownMotionAmongHalfOutliers) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> box(-1.0, 1.0);
  const Pose T = odometry_offset();
  std::vector<Correspondence> pairs;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(box(rng), box(rng), 2.0 + box(rng));
    const bool outlier = i % 2 == 1;
    pairs.push_back({outlier ? Eigen::Vector3d(box(rng), box(rng), box(rng)) : Eigen::Vector3d(T * p), p, 0.01});
  }
  const RigidFit fit = fit_rigid_ransac(pairs);
  EXPECT_EQ(fit.inliers.size(), 100u);
  const auto error = background::view_distance(fit.T_target_source, T);
  EXPECT_LT(error.translation_m, 1e-9);
  EXPECT_LT(error.rotation_deg, 1e-7);
  EXPECT_TRUE(fit_rigid_ransac({pairs[0], pairs[2]}).inliers.empty());  // too few pairs: no fit
}

TEST(KeyframeFeatures, AFrameKeepsOnlyKeypointsWithDepthAndTheFileRoundTrips) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  const auto seq = kitchen();
  const Frame f = load(seq, 0);
  const SensorModel sensor;
  const ViewFeatures features = extract_features(f, sensor, FeatureConfig{});
  // ORB finds its 1000 keypoints; those on depth edges, holes or out of range go.
  std::cout << "features with depth: " << features.size() << " of 1000\n";
  EXPECT_GT(features.size(), 500u);
  EXPECT_LE(features.size(), 1000u);
  for (const auto& p : features.points_camera) EXPECT_TRUE(sensor.in_range(p.z()));
  scenewatch::test::TempDir dir("features");
  ASSERT_TRUE(save_features(dir / "f.bin", {{*f.T_world_camera, features}}).ok());
  auto back = load_features(dir / "f.bin");
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), 1u);
  EXPECT_TRUE(back->front().T_world_camera.isApprox(*f.T_world_camera));
  EXPECT_EQ(back->front().features.descriptors, features.descriptors);
  EXPECT_EQ(back->front().features.points_camera, features.points_camera);
  // Saved with a model, the features find their keyframes again after a reload (ids are renumbered
  // then; the pose names the keyframe).
  background::AppearanceMemory memory;
  for (std::size_t i : {0, 40, 80}) ASSERT_TRUE(memory.add(*background::keyframe_from_frame(load(seq, i))).ok());
  ASSERT_TRUE(memory.save(dir / "model").ok());
  background::AppearanceMemory reloaded;
  ASSERT_TRUE(reloaded.load(dir / "model").ok());
  Relocalizer original;
  EXPECT_TRUE(original.to_save(memory.keyframes()).empty());  // none extracted yet: none saved
  for (const auto& kf : memory.keyframes()) original.features(*kf);
  Relocalizer restored;
  EXPECT_EQ(restored.restore(original.to_save(memory.keyframes()), reloaded.keyframes()), 3u);
  // A truncated file is an error naming it.
  std::filesystem::resize_file(dir / "f.bin", 2000);
  auto truncated = load_features(dir / "f.bin");
  ASSERT_FALSE(truncated.ok());
  EXPECT_NE(truncated.error().message.find("f.bin"), std::string::npos) << truncated.error().message;
  EXPECT_NE(truncated.error().message.find("truncated"), std::string::npos) << truncated.error().message;
}

TEST(Relocalizer, PlacesTheHeldOutHalfOfTheKitchenWithoutAPrior) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  const auto seq = kitchen();
  const background::AppearanceMemory memory = model_half(seq);
  const auto keyframes = memory.keyframes();
  Localizer localizer;
  std::size_t good = 0, placed = 0, wrong = 0, seen_views = 0, good_seen = 0;
  std::vector<double> error_m, error_deg, time_ms;
  std::map<std::string, int> reasons;  // why frames were not placed
  for (std::size_t i = kModelFrames; i < kHeldOutEnd; ++i) {
    Frame f = load(seq, i);
    const Pose truth = *f.T_world_camera;
    f.T_world_camera.reset();  // no prior at all
    const Localization r = localizer.relocalize(f, keyframes);
    time_ms.push_back(r.relocalization_ms);
    // A view the model has: a keyframe within 0.3 m and 20 degrees of the frame's true pose.
    const auto nearest = memory.nearest(truth, 1);
    const bool seen = !nearest.empty() && background::view_distance(nearest.front()->T_world_camera, truth).translation_m <= 0.3 &&
                      background::view_distance(nearest.front()->T_world_camera, truth).rotation_deg <= 20.0;
    seen_views += seen;
    if (!r.placed()) {
      ++reasons[r.reason.substr(0, r.reason.find_first_of(":0123456789", 16))];
      continue;
    }
    ++placed;
    const auto e = background::view_distance(r.T_world_camera, truth);
    error_m.push_back(e.translation_m);
    error_deg.push_back(e.rotation_deg);
    if (within_5cm_5deg(e)) ++good, good_seen += seen;
    if (e.translation_m > 0.2 || e.rotation_deg > 10.0) ++wrong;
  }
  const double n = static_cast<double>(kHeldOutEnd - kModelFrames);
  std::cout << "relocalization of files 250-498 against " << keyframes.size() << " keyframes of files 0-248: placed " << placed
            << " of " << n << ", within 5 cm / 5 deg " << good / n << ", wrong (> 20 cm or 10 deg) " << wrong << ", median error "
            << 1000 * median(error_m) << " mm " << median(error_deg) << " deg, median time " << median(time_ms) << " ms\n";
  std::cout << "  of the " << seen_views << " frames with a keyframe within 0.3 m / 20 deg: within 5 cm / 5 deg "
            << static_cast<double>(good_seen) / std::max<std::size_t>(seen_views, 1) << "\n";
  for (const auto& [why, count] : reasons) std::cout << "  not placed, " << count << "x: " << why << "\n";
  // Measured: 47 of the 125 frames within 5 cm / 5 deg (37.6 %), none placed wrong, median error
  // 25.4 mm / 0.66 deg (the dense alignment's disagreement with the recording's poses at such
  // baselines, docs/localization.md), 25-38 ms per relocalization. The model's 29 keyframes see little of what
  // this half sees: of the 17 frames with a keyframe within 0.3 m / 20 deg, all 17 were placed
  // within 5 cm / 5 deg; the other frames mostly share too few features with any keyframe.
  EXPECT_GE(good, 45u);
  EXPECT_EQ(good_seen, seen_views);
  EXPECT_EQ(wrong, 0u);
  EXPECT_LT(median(error_m), 0.028);
  EXPECT_LT(median(error_deg), 0.8);
}

struct Homing {
  std::size_t keyframes_loaded = 0;
  std::optional<std::size_t> homed_at;  ///< frames after the restart until the first placed one
  std::size_t frames_after = 0, good = 0, events = 0, unplaced_changed = 0, lost_after = 0;
  std::vector<double> error_m, error_deg;
  Pose T_world_odom = Pose::Identity();
  std::vector<std::string> told;  ///< the events: kind, frame, range
  double fraction_good() const { return frames_after ? static_cast<double>(good) / frames_after : 0.0; }
};

// The homing protocol at the working memory: a model of files 0-248 saved, a new memory
// loads it, files 250-498 come with their poses in another odometry frame (35 degrees about z,
// 1.4 m), and, with `drift`, as odometry that drifts by 3 mm and 0.15 degrees per frame (RMS, a
// random walk from `seed`). Until a frame is relocalized nothing changes; then T_world_odom
// places the rest and `refine` keeps it up to date.
Homing run_homing(bool drift, unsigned seed) {
  Homing out;
  const auto seq = kitchen();
  scenewatch::test::TempDir model("homing");
  pipeline::Config config;  // localization.mode given: the model at the recording's poses
  {
    pipeline::WorkingMemory first(config);
    for (std::size_t i = 0; i < kModelFrames; ++i) EXPECT_TRUE(first.process(load(seq, i)).ok());
    EXPECT_TRUE(first.save(model.path()).ok());
  }
  EXPECT_TRUE(std::filesystem::exists(model / "current" / "keyframe-features.bin"));
  config.localization.mode = LocalizationMode::kRefine;
  pipeline::WorkingMemory restarted(config);
  EXPECT_TRUE(restarted.load(model.path()).ok());
  out.keyframes_loaded = restarted.stats().keyframes;
  std::vector<Pose> truth;
  for (std::size_t i = kModelFrames; i < kHeldOutEnd; ++i) truth.push_back(*seq.frames[i].T_world_camera);  // no images read
  const std::vector<Pose> given = drift ? with_drift(truth, 0.003, 0.15, seed) : truth;
  const Pose offset = odometry_offset();
  for (std::size_t k = 0; k < truth.size(); ++k) {
    Frame f = load(seq, kModelFrames + k);
    f.T_world_camera = offset * given[k];
    const auto before = restarted.stats();
    auto r = restarted.process(f);
    EXPECT_TRUE(r.ok()) << r.error().message;
    if (!r.ok()) continue;
    out.events += r->events.size();
    for (const auto& e : r->events) {
      const double range = (e.centroid_world - r->localization.T_world_camera.translation()).norm();
      out.told.push_back(std::string(to_string(e.kind)) + " at frame " + std::to_string(k) + ", " +
                         std::to_string(static_cast<int>(std::lround(100 * range))) + " cm from the camera");
    }
    const auto& where = r->localization;
    if (!out.homed_at) {
      if (!where.placed()) {
        EXPECT_NE(where.reason.find("homing"), std::string::npos) << where.reason;
        const auto after = restarted.stats();
        if (after.map_leaf_nodes != before.map_leaf_nodes || after.keyframes != before.keyframes) ++out.unplaced_changed;
        continue;
      }
      out.homed_at = k;
      EXPECT_TRUE(where.relocalized);
    }
    ++out.frames_after;
    if (!where.placed()) ++out.lost_after;
    const auto e = background::view_distance(where.T_world_camera, truth[k]);
    out.error_m.push_back(e.translation_m);
    out.error_deg.push_back(e.rotation_deg);
    if (within_5cm_5deg(e) && where.placed()) ++out.good;
  }
  const auto odom = restarted.localization("");
  EXPECT_TRUE(odom.ok()) << odom.error().message;
  if (odom.ok()) out.T_world_odom = odom->T_world_odom;
  // An unknown camera is an error naming the known ones.
  const auto unknown = restarted.localization("nope");
  EXPECT_FALSE(unknown.ok());
  if (!unknown.ok()) {
    EXPECT_NE(unknown.error().message.find("nope"), std::string::npos);
  }
  return out;
}

void print(const char* what, const Homing& h) {
  std::cout << what << ": " << h.keyframes_loaded << " keyframes loaded, relocalized at frame "
            << (h.homed_at ? static_cast<long>(*h.homed_at) : -1L) << ", then within 5 cm / 5 deg " << h.fraction_good()
            << ", median error " << 1000 * median(h.error_m) << " mm " << median(h.error_deg) << " deg, lost " << h.lost_after
            << ", events " << h.events << "\n";
  for (const auto& e : h.told) std::cout << "  " << e << "\n";
}

TEST(WorkingMemoryHoming, FindsTheSavedModelsFrameAfterARestart) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  const Homing h = run_homing(false, 0);
  ASSERT_TRUE(h.homed_at.has_value()) << "never homed";
  print("homing", h);
  const auto odom_error = background::view_distance(h.T_world_odom, odometry_offset().inverse());
  std::cout << "  T_world_odom off by " << 1000 * odom_error.translation_m << " mm " << odom_error.rotation_deg << " deg\n";
  EXPECT_EQ(h.unplaced_changed, 0u);
  // Measured: relocalized at the first frame; then all 125 frames within 5 cm / 5 deg, median error
  // 18.4 mm / 0.84 deg, T_world_odom 35 mm / 0.77 deg off at the end, no event; with the colour
  // registered to the depth (sensor.fit_colour_registration) 18.5 mm / 0.74 deg, 38 mm / 0.69 deg,
  // one event. The issue asks for
  // homing within 5 frames, then a median <= 2 cm / 1 degree and >= 95 % within 5 cm / 5 degrees.
  EXPECT_LE(*h.homed_at, 1u);
  EXPECT_GE(h.fraction_good(), 0.98);
  EXPECT_LT(median(h.error_m), 0.021);
  EXPECT_LT(median(h.error_deg), 1.0);
  EXPECT_LT(odom_error.translation_m, 0.045);
  EXPECT_LT(odom_error.rotation_deg, 1.0);
  EXPECT_LE(h.events, 1u);
}

// The same with the drift on top of the offset: the given poses are odometry, and
// T_world_odom must follow them as they drift.
TEST(WorkingMemoryHoming, FollowsDriftingOdometryAfterARestart) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  const Homing h = run_homing(true, 1);
  ASSERT_TRUE(h.homed_at.has_value()) << "never homed";
  print("homing with drift, seed 1", h);
  EXPECT_EQ(h.unplaced_changed, 0u);
  // Measured (seeds 1 / 2 / 3): relocalized at the first frame; then every frame within 5 cm /
  // 5 deg, none lost; median error 17.0 / 29.6 / 16.9 mm and 1.20 / 1.92 / 0.83 deg; 2 / 0 / 0
  // events. The issue asks for a median <= 2 cm / 1 degree and at most 1 event per 100 frames:
  // met on one seed of three.
  EXPECT_LE(*h.homed_at, 1u);
  EXPECT_GE(h.fraction_good(), 0.98);
  EXPECT_EQ(h.lost_after, 0u);
  EXPECT_LT(median(h.error_m), 0.019);
  EXPECT_LT(median(h.error_deg), 1.3);
  EXPECT_LE(h.events, 2u);
}

}  // namespace
}  // namespace scenewatch::localization
