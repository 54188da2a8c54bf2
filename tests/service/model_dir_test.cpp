// The model directory on the real scenewatchd: one daemon per directory (a second one refuses to
// start, naming the first), no unfinished snapshot left behind by a killed or failed save, and a
// save that fails for want of space says so.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <thread>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

proto::Request save_model() {
  return request([](proto::Request& r) { r.mutable_save_model(); });
}

proto::Request ingest_mug() {
  auto frame = io::load_cloud_frame(data_dir() / kMug);
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  proto::Request r;
  if (frame.ok()) *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
  return r;
}

/// The snap-NNNNNN.tmp folders (and a current.tmp link) in a model directory.
std::vector<std::string> unfinished_snapshots(const fs::path& model_dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0) names.push_back(name);
  }
  return names;
}

class ModelDirTest : public ::testing::Test {
 protected:
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();
  }
  std::string model_yaml() const { return "  model_dir: " + model_dir_.string() + "\n"; }

  TempDir tmp_{"model-dir"};
  fs::path model_dir_ = tmp_ / "model";
  Daemon daemon_;
};

TEST_F(ModelDirTest, ASecondDaemonOnTheSameDirectoryRefusesToStartNamingTheFirst) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  service::Client client = daemon_.connect();
  ASSERT_EQ(call(client, ingest_mug()).status().code(), proto::Status::OK);
  ASSERT_EQ(call(client, save_model()).status().code(), proto::Status::OK);
  const fs::path saved = fs::read_symlink(model_dir_ / "current");

  const auto second = run_command({daemon_binary().string(), "--port", "0", "--model-dir", model_dir_.string(),
                                   "--token-file", (tmp_ / "second-token").string()},
                                  tmp_, 20.0);
  std::printf("second daemon on %s: exit %d, %s", model_dir_.c_str(), second.exit_code, second.err.c_str());
  EXPECT_EQ(second.exit_code, 1) << "it must not serve the same model";
  EXPECT_NE(second.err.find("PID " + std::to_string(daemon_.pid())), std::string::npos) << second.err;
  EXPECT_NE(second.err.find(model_dir_.string()), std::string::npos) << second.err;
  EXPECT_EQ(second.out.find("listening on"), std::string::npos) << second.out;
  EXPECT_EQ(fs::read_symlink(model_dir_ / "current"), saved) << "the first daemon's model is untouched";
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);

  // Once the first is gone, the directory is free again (also after a kill: the lock goes with the
  // process).
  client.close();
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0));
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  ::kill(daemon_.pid(), SIGKILL);
  (void)daemon_.terminate();
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  service::Client again = daemon_.connect();
  EXPECT_EQ(call(again, request([](proto::Request& r) { r.mutable_health(); })).health().frames_processed(), 1u)
      << "the saved model is loaded";
}

// Saves killed with SIGKILL part-way leave snap-NNNNNN.tmp folders; the next start removes them
// (and one planted as a killed save leaves it, so the test does not hang on the timing of a kill).
TEST_F(ModelDirTest, UnfinishedSnapshotsAreRemovedAtStartUp) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  {
    service::Client client = daemon_.connect();
    for (int i = 0; i < 3; ++i) ASSERT_EQ(call(client, ingest_mug()).status().code(), proto::Status::OK);
    ASSERT_EQ(call(client, save_model()).status().code(), proto::Status::OK);  // what every restart loads
  }
  int left_behind = 0, left_after_restart = 0;
  for (int round = 0; round < 10; ++round) {
    service::Client client = daemon_.connect();
    ASSERT_TRUE(client.start(save_model()).ok());
    std::this_thread::sleep_for(std::chrono::microseconds(500 * round));
    ::kill(daemon_.pid(), SIGKILL);
    (void)daemon_.terminate();
    left_behind += unfinished_snapshots(model_dir_).empty() ? 0 : 1;
    ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
    const auto left = unfinished_snapshots(model_dir_);
    left_after_restart += static_cast<int>(left.size());
    EXPECT_EQ(left, std::vector<std::string>()) << "round " << round;
  }
  std::printf("10 saves killed with SIGKILL: %d left an unfinished snapshot behind; after the restarts, %d were there\n",
              left_behind, left_after_restart);

  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0));
  const fs::path planted = model_dir_ / "snap-000999.tmp";
  fs::create_directories(planted / "keyframes");
  std::ofstream(planted / "background.ot") << "half a map";
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  EXPECT_FALSE(fs::exists(planted));
  EXPECT_EQ(unfinished_snapshots(model_dir_), std::vector<std::string>());
  service::Client client = daemon_.connect();
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).health().frames_processed(), 3u);
  EXPECT_EQ(call(client, save_model()).status().code(), proto::Status::OK);
  EXPECT_EQ(fs::read_symlink(model_dir_ / "current").string().rfind("snap-", 0), 0u);
}

// A snapshot the pipeline's loader once threw on (a scene.json with its "background" record an
// array; found by fuzz_model_loader, kept in fuzz/regressions/): it is refused naming the record,
// and the daemon stops its start-up with an error naming the model directory, as for any model
// that does not load, instead of terminating on the exception (exit 134 before). A loader that
// still throws is caught by service::load_newest_good the same way.
TEST_F(ModelDirTest, ASnapshotTheLoaderThrowsOnStopsTheStartUpWithAnError) {
  std::ifstream found(source_dir() / "fuzz/regressions/fuzz_model_loader/background_record_array", std::ios::binary);
  const std::string input((std::istreambuf_iterator<char>(found)), std::istreambuf_iterator<char>());
  const char* const names[] = {"scene.json", "background.ot", "events.jsonl", "keyframes/keyframe-000001.color.png",
                               "keyframes/keyframe-000001.depth.png", "keyframes/keyframe-000001.pose.txt",
                               "keyframes/keyframe-000001.intrinsics.txt"};
  const fs::path snapshot = model_dir_ / "snap-000001";
  fs::create_directories(snapshot / "keyframes");
  fs::create_directory_symlink("snap-000001", model_dir_ / "current");
  std::size_t from = 0;
  for (const char* name : names) {
    const std::size_t to = std::min(input.find("\n--8<--\n", from), input.size());
    std::ofstream(snapshot / name, std::ios::binary) << input.substr(from, to - from);
    from = to + 8;
  }
  const auto started = run_command({daemon_binary().string(), "--port", "0", "--model-dir", model_dir_.string(),
                                    "--token-file", (tmp_ / "token").string()},
                                   tmp_, 30.0);
  EXPECT_EQ(started.exit_code, 1) << started.err;
  EXPECT_NE(started.err.find("records its background as array"), std::string::npos) << started.err;
  EXPECT_NE(started.err.find("repair or move the directory"), std::string::npos) << started.err;
}

// LoadModel of a snapshot whose scene.json is not JSON and holds bytes that are not UTF-8 (found by
// fuzz_model_loader): the parser's message quotes them, and a Response whose status message is
// not UTF-8 cannot be parsed by the client (protobuf refuses it), so the client saw a broken
// connection instead of the refusal. The message is now made UTF-8 ('?' for such bytes).
TEST_F(ModelDirTest, ARefusalQuotingBytesThatAreNotUtf8ReachesTheClient) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  fs::create_directories(model_dir_ / "snap-000001");
  std::ofstream(model_dir_ / "snap-000001" / "scene.json", std::ios::binary) << "{\n  \"b\xea\xff\": t_id\": 1\n}";
  fs::create_directory_symlink("snap-000001", model_dir_ / "current");
  service::Client client = daemon_.connect();
  auto reply = client.call(request([](proto::Request& r) { r.mutable_load_model(); }), kCallTimeoutS);
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  EXPECT_EQ(reply->status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(reply->status().message().find("scene.json"), std::string::npos) << reply->status().message();
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);
}

// A model directory on a file system that is full: the save fails with the system's reason, and
// leaves no unfinished snapshot. The daemon runs in a mount namespace of its own (unshare) with a
// 128 KiB tmpfs on its model directory: room for the class store (about 80 kB), not for the map of
// the mug frame (120 kB).
TEST_F(ModelDirTest, ASaveOnAFullDiskSaysWhyAndLeavesNothingBehind) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  if (run_command({"/usr/bin/unshare", "-rm", "true"}, tmp_).exit_code != 0) {
    GTEST_SKIP() << "unshare -rm is not permitted here (user namespaces are off)";
  }
  fs::create_directories(model_dir_);
  daemon_.set_command_prefix({"/usr/bin/unshare", "-rm", "/bin/sh", "-c",
                              "mount -t tmpfs -o size=128k tmpfs \"$0\" && exec \"$@\"", model_dir_.string()});
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, model_yaml()));
  service::Client client = daemon_.connect();
  ASSERT_EQ(call(client, ingest_mug()).status().code(), proto::Status::OK);
  const auto saved = call(client, save_model());
  std::printf("SaveModel on a 128 KiB tmpfs: %s: %s\n", service::to_string(saved.status().code()).c_str(),
              saved.status().message().c_str());
  EXPECT_EQ(saved.status().code(), proto::Status::IO_ERROR);
  EXPECT_NE(saved.status().message().find("No space left on device"), std::string::npos) << saved.status().message();
  // The tmpfs is seen through the daemon's own root (its mount namespace).
  const fs::path seen = fs::path("/proc") / std::to_string(daemon_.pid()) / "root" / model_dir_.relative_path();
  ASSERT_TRUE(fs::is_directory(seen)) << seen;
  EXPECT_EQ(unfinished_snapshots(seen), std::vector<std::string>());
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);
}

}  // namespace
}  // namespace scenewatch::test
