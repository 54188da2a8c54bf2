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
  ASSERT_TRUE(load("background:\n  resolution_m: 0.05\n  max_range_m: 3\n  fast_insertion: false\n"
                   "segmentation:\n  voxel_size_m: 0.02\n  up_vector: [0, 0, 1]\n  seed: 9\n  max_planes: 2\n"
                   "tracking:\n  match_distance_m: 0.1\nevents:\n  max_log: 50\n",
                   c)
                  .ok());
  EXPECT_DOUBLE_EQ(c.background.resolution_m, 0.05);
  EXPECT_DOUBLE_EQ(c.background.max_range_m, 3);
  EXPECT_FALSE(c.background.fast_insertion);
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
  auto missing = load_yaml_file(dir_ / "absent.yaml", pipeline_sections());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("absent.yaml"), std::string::npos);
}

TEST_F(ConfigTest, ShippedConfigIsValid) {
  const fs::path shipped = test::source_dir() / "config/scenewatchd.yaml";
  if (!fs::exists(shipped)) GTEST_SKIP() << "no shipped config yet";
  std::vector<std::string> sections = pipeline_sections();
  sections.push_back("server");
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
