#include "scenewatch/service/daemon_config.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "test_data.h"

namespace scenewatch::service {
namespace {
namespace fs = std::filesystem;

class ServerConfigTest : public ::testing::Test {
 protected:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
  fs::path write(const std::string& text) {
    const fs::path path = tmp_ / "scenewatchd.yaml";
    std::ofstream(path) << text;
    return path;
  }
  fs::path tmp_ = test::make_temp_dir("config");
};

TEST_F(ServerConfigTest, ShippedConfigListsTheDefaults) {
  auto loaded = load_daemon_config(test::source_dir() / "config" / "scenewatchd.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const ServerConfig defaults;
  const ServerConfig& s = loaded->server;
  EXPECT_EQ(s.address, defaults.address);
  EXPECT_EQ(s.port, kDefaultPort);
  EXPECT_EQ(s.max_message_bytes, defaults.max_message_bytes);
  EXPECT_DOUBLE_EQ(s.read_timeout_s, defaults.read_timeout_s);
  EXPECT_DOUBLE_EQ(s.frame_timeout_s, defaults.frame_timeout_s);
  EXPECT_EQ(s.max_file_bytes, defaults.max_file_bytes);
  EXPECT_EQ(s.max_queued_bytes, defaults.max_queued_bytes);
  EXPECT_EQ(s.max_buffered_bytes, defaults.max_buffered_bytes);
  EXPECT_EQ(s.keep_snapshots, defaults.keep_snapshots);
  EXPECT_EQ(s.max_connections, defaults.max_connections);
  EXPECT_EQ(s.io_threads, defaults.io_threads);
  EXPECT_TRUE(s.data_roots.empty());
  EXPECT_TRUE(s.model_dir.empty());
  EXPECT_TRUE(s.token_file.empty()) << "empty: the daemon and the CLI use ~/.scenewatch/token";
  EXPECT_EQ(s.http_port, 0) << "no live view unless asked";
  EXPECT_EQ(s.http_bind, defaults.http_bind);
  EXPECT_EQ(s.http_bind, "127.0.0.1");
  EXPECT_EQ(s.http_three_js, defaults.http_three_js);
  EXPECT_EQ(s.http_max_streams, defaults.http_max_streams);
  EXPECT_DOUBLE_EQ(s.http_heartbeat_s, defaults.http_heartbeat_s);
  EXPECT_DOUBLE_EQ(s.http_stream_timeout_s, defaults.http_stream_timeout_s);
  EXPECT_DOUBLE_EQ(loaded->pipeline.workspace_radius_m, pipeline::Config{}.workspace_radius_m);
  EXPECT_TRUE(loaded->ontology.classes_file.empty()) << "empty: the shipped config/ontology.yaml";
  const pipeline::Config pipeline_defaults;
  EXPECT_DOUBLE_EQ(loaded->pipeline.background.resolution_m, pipeline_defaults.background.resolution_m);
  EXPECT_DOUBLE_EQ(loaded->pipeline.segmentation.voxel_size_m, pipeline_defaults.segmentation.voxel_size_m);
  EXPECT_EQ(loaded->pipeline.segmentation.min_cluster_points, pipeline_defaults.segmentation.min_cluster_points);
  EXPECT_EQ(loaded->pipeline.max_event_log, pipeline_defaults.max_event_log);
}

TEST_F(ServerConfigTest, TheLiveViewsStreamKeysAndTheWorkspaceAreReadAndChecked) {
  auto loaded = load_daemon_config(write("server:\n  http_max_streams: 4\n  http_heartbeat_s: 0.5\n"
                                         "  http_stream_timeout_s: 5\nworkspace:\n  radius_m: 25\n"));
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->server.http_max_streams, 4u);
  EXPECT_DOUBLE_EQ(loaded->server.http_heartbeat_s, 0.5);
  EXPECT_DOUBLE_EQ(loaded->server.http_stream_timeout_s, 5.0);
  EXPECT_DOUBLE_EQ(loaded->pipeline.workspace_radius_m, 25.0);
  for (const auto& [yaml, key] : std::vector<std::pair<std::string, std::string>>{
           {"server:\n  http_max_streams: 0\n", "server.http_max_streams"},
           {"server:\n  http_heartbeat_s: 0\n", "server.http_heartbeat_s"},
           {"server:\n  http_stream_timeout_s: -1\n", "server.http_stream_timeout_s"},
           {"workspace:\n  radius_m: -5\n", "workspace.radius_m"},
           {"workspace:\n  radius: 5\n", "workspace.radius: unknown key"}}) {
    auto bad = load_daemon_config(write(yaml));
    ASSERT_FALSE(bad.ok()) << yaml;
    EXPECT_NE(bad.error().message.find(key), std::string::npos) << bad.error().message;
  }
}

TEST_F(ServerConfigTest, RelativePathsAreRelativeToTheConfigFile) {
  fs::create_directories(tmp_ / "data");
  auto loaded = load_daemon_config(
      write("server:\n  data_roots: [data]\n  model_dir: state/model\n  token_file: state/token\n  port: 0\n"));
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->server.token_file, tmp_ / "state" / "token");
  ASSERT_EQ(loaded->server.data_roots.size(), 1u);
  EXPECT_EQ(loaded->server.data_roots[0], tmp_ / "data");
  EXPECT_EQ(loaded->server.model_dir, tmp_ / "state" / "model");
  EXPECT_EQ(loaded->server.port, 0);
  auto classes = load_daemon_config(write("ontology:\n  classes_file: my/classes.yaml\n"));
  ASSERT_TRUE(classes.ok()) << classes.error().message;
  EXPECT_EQ(classes->ontology.classes_file, tmp_ / "my" / "classes.yaml");
}

TEST_F(ServerConfigTest, ErrorsNameTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"server:\n  bogus: 1\n", "server.bogus"},
      {"server:\n  port: 70000\n", "server.port"},
      {"server:\n  port: -1\n", "server.port"},
      {"server:\n  port: seven\n", "server.port"},
      {"server:\n  read_timeout_s: 0\n", "server.read_timeout_s"},
      {"server:\n  frame_timeout_s: -1\n", "server.frame_timeout_s"},
      {"server:\n  max_buffered_bytes: 1000\n", "server.max_buffered_bytes"},
      {"server:\n  max_message_bytes: 10\n", "server.max_message_bytes"},
      {"server:\n  max_queued_bytes: 100\n", "server.max_queued_bytes"},
      {"server:\n  io_threads: 0\n", "server.io_threads"},
      {"server:\n  http_port: 70000\n", "server.http_port"},
      {"server:\n  http_port: 7878\n  port: 7878\n", "server.http_port"},
      {"server:\n  http_port: 8080\n  http_bind: ''\n", "server.http_bind"},
      {"server:\n  data_roots: [does-not-exist]\n", "server.data_roots[0]"},
      {"server: 5\n", "server"},
      {"segmentation:\n  voxel_size_m: -1\n", "segmentation.voxel_size_m"},
      {"bogus_section:\n  a: 1\n", "bogus_section"},
      {"ontology:\n  classes: x.yaml\n", "ontology.classes"},
      {"ontology: 5\n", "ontology"},
  };
  for (const auto& [text, key] : cases) {
    auto loaded = load_daemon_config(write(text));
    ASSERT_FALSE(loaded.ok()) << text;
    EXPECT_NE(loaded.error().message.find(key), std::string::npos) << text << " -> " << loaded.error().message;
  }
}

TEST_F(ServerConfigTest, MissingFileIsNotFound) {
  auto loaded = load_daemon_config(tmp_ / "nope.yaml");
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().code, ErrorCode::kNotFound);
  EXPECT_NE(loaded.error().message.find("nope.yaml"), std::string::npos);
}

}  // namespace
}  // namespace scenewatch::service
