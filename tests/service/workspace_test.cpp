// Poses and points within the workspace (issue 34): the real scenewatchd refuses a frame whose
// pose or points lie outside workspace.radius_m of the world origin, with a message naming the
// bound and the key, and changes nothing; a frame's `source` label is cut to a stated length.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

/// The mug frame, placed in the world by a translation of `t` (no rotation).
proto::Request mug_at(const Eigen::Vector3d& t, const std::string& source = "") {
  auto frame = io::load_cloud_frame(data_dir() / kMug);
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  proto::Request r;
  if (!frame.ok()) return r;
  Pose T = Pose::Identity();
  T.translation() = t;
  frame->T_world_camera = T;
  if (!source.empty()) frame->source = source;
  *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
  return r;
}

proto::Request health() {
  return request([](proto::Request& r) { r.mutable_health(); });
}

class WorkspaceTest : public ::testing::Test {
 protected:
  void SetUp() override { SCENEWATCH_REQUIRE_DATA(kMug); }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();
  }
  TempDir tmp_{"workspace"};
  Daemon daemon_;
};

TEST_F(WorkspaceTest, APoseOrPointsBeyondAKilometreAreRefusedNamingTheBound) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, ""));
  service::Client client = daemon_.connect();
  const auto far_pose = call(client, mug_at({1e30, 0, 0}));
  std::printf("a pose at x = 1e30: %s\n", far_pose.status().message().c_str());
  EXPECT_EQ(far_pose.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(far_pose.status().message().find("workspace.radius_m"), std::string::npos) << far_pose.status().message();
  EXPECT_NE(far_pose.status().message().find("1000 m"), std::string::npos) << far_pose.status().message();

  // The camera inside, its points (about a metre in front of it) outside.
  const auto far_points = call(client, mug_at({999.9, 0, 0}));
  std::printf("a pose at x = 999.9: %s\n", far_points.status().message().c_str());
  EXPECT_EQ(far_points.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(far_points.status().message().find("points"), std::string::npos) << far_points.status().message();
  EXPECT_NE(far_points.status().message().find("workspace.radius_m"), std::string::npos) << far_points.status().message();

  EXPECT_EQ(call(client, health()).health().frames_processed(), 0u) << "nothing was processed";
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_get_objects(); })).objects().objects_size(), 0);
  EXPECT_EQ(call(client, mug_at({500, -300, 2})).status().code(), proto::Status::OK) << "inside: served";
}

TEST_F(WorkspaceTest, TheBoundIsConfigurable) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "workspace:\n  radius_m: 5\n"));
  service::Client client = daemon_.connect();
  const auto outside = call(client, mug_at({10, 0, 0}));
  EXPECT_EQ(outside.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(outside.status().message().find("5 m"), std::string::npos) << outside.status().message();
  EXPECT_EQ(call(client, mug_at({1, 0, 0})).status().code(), proto::Status::OK);

  const fs::path bad = tmp_ / "bad.yaml";
  std::ofstream(bad) << "workspace:\n  radius_m: 0\n";
  const auto refused = run_command({daemon_binary().string(), "--config", bad.string()}, tmp_);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("workspace.radius_m"), std::string::npos) << refused.err;
}

// A 1 MB source label: the frame is served, and messages that name the source carry a cut label
// that says it was cut, not a megabyte.
TEST_F(WorkspaceTest, AMegabyteSourceIsCutToAStatedLength) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, ""));
  service::Client client = daemon_.connect();
  const std::string source(1 << 20, 's');
  const auto refused = call(client, mug_at({1e30, 0, 0}, source));
  EXPECT_EQ(refused.status().code(), proto::Status::INVALID_ARGUMENT);
  std::printf("the message of a refused frame with a 1 MB source: %zu bytes\n", refused.status().message().size());
  EXPECT_LT(refused.status().message().size(), 1024u);
  EXPECT_NE(refused.status().message().find("cut from 1048576 bytes"), std::string::npos)
      << refused.status().message().substr(0, 400);
  EXPECT_EQ(call(client, mug_at({0, 0, 0}, source)).status().code(), proto::Status::OK);
  EXPECT_LT(daemon_.log().size(), 64u * 1024) << "the log holds no megabyte label";
}

}  // namespace
}  // namespace scenewatch::test
