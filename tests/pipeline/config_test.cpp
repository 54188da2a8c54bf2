// Strict configuration: unknown keys and bad values stop start-up with the key's name.
#include <gtest/gtest.h>

#include <fstream>

#include "scenewatch/pipeline/config_loader.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {
namespace fs = std::filesystem;

class ConfigTest : public ::testing::Test {
 protected:
  Status load(const std::string& yaml, Config& c) {
    std::ofstream(dir_ / "c.yaml") << yaml;
    auto root = load_yaml_file(dir_ / "c.yaml", pipeline_sections());
    if (!root) return root.error();
    return read_pipeline_config(*root, c);
  }
  std::string error_of(const std::string& yaml) {
    Config c;
    auto st = load(yaml, c);
    return st.ok() ? std::string("(no error)") : st.error().message;
  }
  test::TempDir dir_{"config"};
};

TEST_F(ConfigTest, ReadsEveryKnownKey) {
  Config c;
  ASSERT_TRUE(load("background:\n  resolution_m: 0.05\n  max_range_m: 3\n  fast_insertion: false\n  ray_stop_after: 4\n"
                   "segmentation:\n  voxel_size_m: 0.02\n  up_vector: [0, 0, 1]\n  seed: 9\n  max_planes: 2\n"
                   "tracking:\n  match_distance_m: 0.1\nevents:\n  max_log: 50\n",
                   c)
                  .ok());
  EXPECT_DOUBLE_EQ(c.background.resolution_m, 0.05);
  EXPECT_DOUBLE_EQ(c.background.max_range_m, 3);
  EXPECT_FALSE(c.background.fast_insertion);
  EXPECT_EQ(c.background.ray_stop_after, 4);
  EXPECT_DOUBLE_EQ(c.segmentation.voxel_size_m, 0.02);
  ASSERT_TRUE(c.segmentation.up.has_value());
  EXPECT_DOUBLE_EQ(c.segmentation.up->z(), 1.0);
  EXPECT_EQ(c.segmentation.seed, 9u);
  EXPECT_EQ(c.segmentation.max_planes, 2);
  EXPECT_DOUBLE_EQ(c.tracking.match_distance_m, 0.1);
  EXPECT_EQ(c.max_event_log, 50u);
}

TEST_F(ConfigTest, EmptyFileMeansDefaults) {
  Config c;
  ASSERT_TRUE(load("", c).ok());
  EXPECT_DOUBLE_EQ(c.background.resolution_m, background::Config{}.resolution_m);
}

TEST_F(ConfigTest, ErrorsNameTheKey) {
  EXPECT_NE(error_of("background:\n  resolution: 0.05\n").find("background.resolution: unknown key"), std::string::npos);
  EXPECT_NE(error_of("segmentaton:\n  seed: 1\n").find("unknown section 'segmentaton'"), std::string::npos);
  EXPECT_NE(error_of("background:\n  resolution_m: -1\n").find("background.resolution_m"), std::string::npos);
  EXPECT_NE(error_of("background:\n  resolution_m: fast\n").find("background.resolution_m: cannot read value"), std::string::npos);
  EXPECT_NE(error_of("segmentation:\n  up_vector: [0, 1]\n").find("segmentation.up_vector"), std::string::npos);
  EXPECT_NE(error_of("segmentation:\n  up_vector: [0, 0, 0]\n").find("up_vector"), std::string::npos);
  EXPECT_NE(error_of("tracking: 5\n").find("tracking: must be a mapping"), std::string::npos);
  EXPECT_NE(error_of("background:\n  resolution_m: [1\n").find("line"), std::string::npos) << "syntax errors name the line";
  EXPECT_NE(error_of("- a\n- b\n").find("top level"), std::string::npos);
  // Keys that are not plain names (found by fuzz_config: converting them threw, and the daemon
  // ended in std::terminate instead of naming the problem).
  EXPECT_NE(error_of("? [a, b]\n: 1\n").find("a key must be a plain name, got '[a, b]'"), std::string::npos)
      << error_of("? [a, b]\n: 1\n");
  EXPECT_NE(error_of("background:\n  ? {x: 1}\n  : 2\n").find("background: a key must be a plain name"),
            std::string::npos)
      << error_of("background:\n  ? {x: 1}\n  : 2\n");
  auto missing = load_yaml_file(dir_ / "absent.yaml", pipeline_sections());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("absent.yaml"), std::string::npos);
}

// The whole text of each kind of message the reader writes, as users have seen it; moving the
// reader onto the shared YAML helper (yaml_value.h) kept every word.
TEST_F(ConfigTest, MessagesKeepTheirWords) {
  const std::string file = "'" + (dir_ / "c.yaml").string() + "'";
  EXPECT_EQ(error_of("background:\n  resolution: 0.05\n"), "background.resolution: unknown key");
  EXPECT_EQ(error_of("background:\n  resolution_m: fast\n"), "background.resolution_m: cannot read value 'fast'");
  EXPECT_EQ(error_of("tracking:\n  confirm_frames: [1, 2]\n"), "tracking.confirm_frames: cannot read value '[1, 2]'");
  EXPECT_EQ(error_of("change:\n  enabled: maybe\n"), "change.enabled: cannot read value 'maybe'");
  EXPECT_EQ(error_of("tracking: 5\n"), "tracking: must be a mapping of keys to values");
  EXPECT_EQ(error_of("segmentation:\n  up_vector: [0, 1]\n"), "segmentation.up_vector: must be [x, y, z] or null");
  EXPECT_EQ(error_of("localization:\n  mode: fly\n"),
            "localization.mode: localization mode 'fly': expected given, refine or track");
  EXPECT_EQ(error_of("background:\n  ? {x: 1}\n  : 2\n"), "background: a key must be a plain name, got '{x: 1}'");
  EXPECT_EQ(error_of("? [a, b]\n: 1\n"), file + ": a key must be a plain name, got '[a, b]'");
  EXPECT_EQ(error_of("segmentaton:\n  seed: 1\n"), file + ": unknown section 'segmentaton'");
}

TEST_F(ConfigTest, ShippedConfigIsValid) {
  const fs::path shipped = test::source_dir() / "config/scenewatchd.yaml";
  if (!fs::exists(shipped)) GTEST_SKIP() << "no shipped config yet";
  std::vector<std::string> sections = pipeline_sections();
  sections.push_back("server");    // the daemon's own sections
  sections.push_back("ontology");
  auto root = load_yaml_file(shipped, sections);
  ASSERT_TRUE(root.ok()) << root.error().message;
  Config c;
  auto st = read_pipeline_config(*root, c);
  EXPECT_TRUE(st.ok()) << st.error().message;
  // The shipped file documents the defaults: its values are the built-in ones.
  const Config d;
  EXPECT_EQ(c.appearance.keyframe_min_translation_m, d.appearance.keyframe_min_translation_m);
  EXPECT_EQ(c.appearance.max_keyframes, d.appearance.max_keyframes);
  EXPECT_EQ(c.appearance.mesh_stride_px, d.appearance.mesh_stride_px);
  EXPECT_EQ(c.surprise.prior.b0, d.surprise.prior.b0);
  EXPECT_EQ(c.surprise.min_samples, d.surprise.min_samples);
  EXPECT_EQ(c.surprise.view.sample_step_px, d.surprise.view.sample_step_px);
  EXPECT_EQ(c.surprise.regions.threshold_high, d.surprise.regions.threshold_high);
  EXPECT_EQ(c.surprise.robust.photometric, d.surprise.robust.photometric);
  EXPECT_EQ(c.surprise.robust.align_radius_px, d.surprise.robust.align_radius_px);
  EXPECT_EQ(c.surprise.robust.align_min_kl, d.surprise.robust.align_min_kl);
  EXPECT_EQ(c.surprise.familiar_after_frames, d.surprise.familiar_after_frames);
  EXPECT_EQ(c.tracking.confirm_frames, d.tracking.confirm_frames);
  EXPECT_EQ(c.tracking.gone_frames, d.tracking.gone_frames);
  EXPECT_EQ(c.tracking.max_range_m, d.tracking.max_range_m);
  EXPECT_EQ(c.fusion.persistence_frames, d.fusion.persistence_frames);
  EXPECT_EQ(c.fusion.match_m, d.fusion.match_m);
  EXPECT_EQ(c.fusion.margin_m, d.fusion.margin_m);
  EXPECT_EQ(c.fusion.zone_frames, d.fusion.zone_frames);
  EXPECT_EQ(c.sensor.profile, d.sensor.profile);
  EXPECT_EQ(c.sensor.axial_base_m, d.sensor.axial_base_m);
  EXPECT_EQ(c.sensor.axial_quad_per_m, d.sensor.axial_quad_per_m);
  EXPECT_EQ(c.sensor.axial_offset_m, d.sensor.axial_offset_m);
  EXPECT_EQ(c.sensor.lateral_px, d.sensor.lateral_px);
  EXPECT_EQ(c.sensor.min_range_m, d.sensor.min_range_m);
  EXPECT_EQ(c.sensor.max_range_m, d.sensor.max_range_m);
  EXPECT_EQ(c.sensor.border_px, d.sensor.border_px);
  EXPECT_EQ(c.sensor.registration_px, d.sensor.registration_px);
  EXPECT_EQ(c.sensor.pose_sigma_m, d.sensor.pose_sigma_m);
  EXPECT_EQ(c.sensor.pose_sigma_deg, d.sensor.pose_sigma_deg);
  EXPECT_EQ(c.change.trusted_pixels_only, d.change.trusted_pixels_only);
  EXPECT_EQ(c.change.measure_pose, d.change.measure_pose);
  EXPECT_EQ(c.change.witness_per_camera, d.change.witness_per_camera);
  EXPECT_EQ(c.change.incidence_aware, d.change.incidence_aware);
  EXPECT_EQ(c.change.see_through_dark, d.change.see_through_dark);
}

TEST_F(ConfigTest, StreamKeysAreChecked) {
  EXPECT_NE(error_of("surprise:\n  align_radius_px: 9\n").find("surprise.align_radius_px"), std::string::npos);
  EXPECT_NE(error_of("surprise:\n  familiar_after_frames: -1\n").find("surprise.familiar_after_frames"), std::string::npos);
  EXPECT_NE(error_of("tracking:\n  confirm_frames: 0\n").find("tracking.confirm_frames"), std::string::npos);
  EXPECT_NE(error_of("tracking:\n  max_range_m: -2\n").find("tracking.max_range_m"), std::string::npos);
  EXPECT_NE(error_of("events:\n  appearance_persistence_frames: 0\n").find("events.appearance_persistence_frames"),
            std::string::npos);
  EXPECT_NE(error_of("events:\n  merge_margin_m: 2\n").find("events.merge_margin_m"), std::string::npos);
  EXPECT_NE(error_of("events:\n  silence: 3\n").find("silence"), std::string::npos) << "unknown key";
}

TEST_F(ConfigTest, AppearanceAndSurpriseKeysAreChecked) {
  EXPECT_NE(error_of("surprise:\n  b0: -1\n").find("surprise.b0"), std::string::npos);
  EXPECT_NE(error_of("surprise:\n  threshold_high: 1\n  threshold_low: 2\n").find("threshold_high"), std::string::npos);
  EXPECT_NE(error_of("surprise:\n  max_samples: 9\n").find("max_samples"), std::string::npos);
  EXPECT_NE(error_of("appearance:\n  mesh_stride_px: 0\n").find("appearance.mesh_stride_px"), std::string::npos);
  EXPECT_NE(error_of("appearance:\n  keyframes: 3\n").find("keyframes"), std::string::npos) << "unknown key";
}

}  // namespace
}  // namespace scenewatch::pipeline
