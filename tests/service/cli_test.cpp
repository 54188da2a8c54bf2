// The scenewatch CLI, run as a user would: offline segmentation, usage errors, and the daemon
// commands against a real scenewatchd.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "daemon_harness.h"
#include "scenewatch/io/cloud_io.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

class CliTest : public ::testing::Test {
 protected:
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  CommandResult cli(std::vector<std::string> args) {
    args.insert(args.begin(), cli_binary().string());
    return run_command(args, tmp_);
  }

  /// The CLI against the test's daemon.
  CommandResult remote(std::vector<std::string> args) {
    args.push_back("--port");
    args.push_back(std::to_string(daemon_.port()));
    args.push_back("--token-file");
    args.push_back(daemon_.token_file().string());
    return cli(std::move(args));
  }

  static json parse(const std::string& text) {
    try {
      return json::parse(text);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not JSON (" << e.what() << "):\n" << text;
      return json();
    }
  }

  fs::path tmp_ = make_temp_dir("cli");
  Daemon daemon_;
};

TEST_F(CliTest, SegmentPrintsPlanesAndObjectsWithIndices) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  const auto result = cli({"segment", (data_dir() / kMug).string(), "--json", "--out", (tmp_ / "out").string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json j = parse(result.out);
  ASSERT_TRUE(j.is_object());
  ASSERT_GE(j.at("planes").size(), 1u);
  ASSERT_GE(j.at("objects").size(), 1u);
  const std::size_t points = j.at("points").get<std::size_t>();
  EXPECT_EQ(points, 640u * 480u);
  for (const auto& object : j.at("objects")) {
    const auto& indices = object.at("indices");
    ASSERT_FALSE(indices.empty());
    EXPECT_EQ(indices.size(), object.at("point_count").get<std::size_t>());
    for (const auto& i : indices) {
      ASSERT_GE(i.get<long>(), 0);
      ASSERT_LT(i.get<std::size_t>(), points);
    }
  }
  // --out: one PCD per object and per plane, holding exactly their points.
  auto first = io::read_cloud(tmp_ / "out" / "object_000.pcd");
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_EQ(first->cloud->size(), j.at("objects")[0].at("point_count").get<std::size_t>());
  EXPECT_TRUE(fs::exists(tmp_ / "out" / "plane_000.pcd"));
  EXPECT_EQ(j.at("written").size(), j.at("objects").size() + j.at("planes").size());

  const auto text = cli({"segment", (data_dir() / kMug).string()});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("object 0"), std::string::npos) << text.out;
}

TEST_F(CliTest, HelpAndUsageErrors) {
  EXPECT_EQ(cli({"--help"}).exit_code, 0);
  for (const char* command : {"health", "stats", "ingest", "planes", "objects", "occupancy", "clear-box", "reset",
                              "save", "load", "events", "watch", "segment"}) {
    const auto result = cli({command, "--help"});
    EXPECT_EQ(result.exit_code, 0) << command;
    EXPECT_NE(result.out.find("--json"), std::string::npos) << command << ":\n" << result.out;
  }
  EXPECT_EQ(cli({}).exit_code, 2);
  EXPECT_EQ(cli({"bogus"}).exit_code, 2);
  EXPECT_EQ(cli({"segment"}).exit_code, 2);
  EXPECT_EQ(cli({"occupancy", "1", "2"}).exit_code, 2);
  EXPECT_EQ(cli({"clear-box", "1", "2", "3"}).exit_code, 2);
}

TEST_F(CliTest, MissingFileIsAnErrorNamingIt) {
  const auto result = cli({"segment", (tmp_ / "no-such-cloud.pcd").string(), "--json"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("no-such-cloud.pcd"), std::string::npos) << result.err;
  EXPECT_TRUE(result.out.empty()) << result.out;
}

TEST_F(CliTest, NoDaemonIsAnErrorNamingTheEndpoint) {
  // A port that was free a moment ago.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const int port = ntohs(addr.sin_port);
  ::close(fd);

  const auto result = cli({"health", "--port", std::to_string(port)});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("127.0.0.1:" + std::to_string(port)), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("scenewatchd"), std::string::npos) << result.err;
}

TEST_F(CliTest, DaemonCommands) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  fs::create_directories(tmp_ / "data");
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "  data_roots: [" + (data_dir() / "pcl").string() + "]\n  model_dir: " +
                                                  (tmp_ / "model").string() + "\n"));
  const std::string mug = (data_dir() / kMug).string();

  auto result = remote({"health", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(parse(result.out).at("status"), "OK");

  result = remote({"ingest", mug, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  json frame = parse(result.out);
  EXPECT_GE(frame.at("planes").size(), 1u);
  EXPECT_GE(frame.at("clusters").size(), 1u);
  EXPECT_EQ(frame.at("source"), mug);

  result = remote({"ingest", "--server-side", mug});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("frame 1"), std::string::npos) << result.out;

  result = remote({"ingest", "--server-side", (tmp_ / "cli.yaml").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("PERMISSION_DENIED"), std::string::npos) << result.err;

  result = remote({"objects", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::size_t objects = parse(result.out).at("objects").size();
  EXPECT_GE(objects, 1u);

  result = remote({"planes", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_GE(parse(result.out).at("planes").size(), 1u);

  result = remote({"events", "--since", "0", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json events = parse(result.out).at("events");
  EXPECT_EQ(events.size(), 0u) << "the same scene twice: nothing changed, nothing to report";

  result = remote({"occupancy", "0", "0", "0.5", "--box", "-1", "-1", "0", "1", "1", "3", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  json occupancy = parse(result.out);
  EXPECT_EQ(occupancy.at("points").size(), 1u);
  EXPECT_EQ(occupancy.at("box").at("state"), "occupied");

  result = remote({"stats", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(parse(result.out).at("frames_processed"), 2);

  result = remote({"save", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(parse(result.out).at("model_dir"), (tmp_ / "model").string());
  ASSERT_EQ(remote({"reset"}).exit_code, 0);
  result = remote({"objects", "--json"});
  EXPECT_EQ(parse(result.out).at("objects").size(), 0u);
  result = remote({"load", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(parse(result.out).at("objects").get<std::size_t>(), objects);

  result = remote({"clear-box", "-10", "-10", "-10", "10", "10", "10", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_GT(parse(result.out).at("voxels_changed").get<std::size_t>(), 0u);

  result = remote({"clear-box", "1", "1", "1", "0", "0", "0"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("INVALID_ARGUMENT"), std::string::npos) << result.err;
}

TEST_F(CliTest, SurpriseOfflineOnAnMosdPair) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn12.pcd");
  const fs::path learn = data_dir() / "mosd/learn";
  // learn12 -> learn13: same camera, an object is added.
  const auto result = cli({"surprise", (learn / "learn13.pcd").string(), "--reference", (learn / "learn12.pcd").string(),
                           "--out", (tmp_ / "heat.png").string(), "--raw", (tmp_ / "kl.tiff").string(), "--expected",
                           (tmp_ / "expected.png").string(), "--mesh", (tmp_ / "mesh.ply").string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json j = parse(result.out);
  EXPECT_EQ(j.at("width"), 640);
  EXPECT_EQ(j.at("keyframes"), 1);
  EXPECT_GT(j.at("known_pixels").get<std::size_t>(), 100000u);
  ASSERT_GE(j.at("regions").size(), 1u);
  EXPECT_EQ(j.at("regions")[0].at("kind"), "APPEARANCE_CHANGE");
  EXPECT_TRUE(j.at("regions")[0].at("evidence").contains("kl_peak_luminance"));
  for (const char* name : {"heat.png", "expected.png", "mesh.ply"}) EXPECT_GT(fs::file_size(tmp_ / name), 1000u) << name;
  EXPECT_GE(fs::file_size(tmp_ / "kl.tiff"), 640u * 480u * 4u);
  auto mesh = io::read_mesh_ply(tmp_ / "mesh.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  EXPECT_GT(mesh->triangles.size(), 10000u);

  // Without an observation there is nothing to compare; a frame number past the end is named.
  auto bad = cli({"surprise", "--reference", (learn / "learn12.pcd").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("observed frame"), std::string::npos) << bad.err;
  bad = cli({"surprise", (source_dir() / "sample_clouds/tabletop").string() + ":999", "--reference",
             (source_dir() / "sample_clouds/tabletop").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find(":999"), std::string::npos) << bad.err;
}

TEST_F(CliTest, ReplayTellsTheStreamAndCountsIt) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  const fs::path learn = data_dir() / "mosd/learn";
  const std::string before = (learn / "learn12.pcd").string(), after = (learn / "learn13.pcd").string();
  // An object put on the table, seen in three frames: told once, on the fourth frame (index 3).
  auto result = cli({"replay", before, after, after, after, after, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::vector<json> lines;
  std::istringstream in(result.out);
  for (std::string line; std::getline(in, line);) lines.push_back(parse(line));
  ASSERT_GE(lines.size(), 2u);
  const json summary = lines.back();
  EXPECT_TRUE(summary.at("summary").get<bool>());
  EXPECT_EQ(summary.at("frames"), 5);
  EXPECT_EQ(summary.at("events").get<std::size_t>(), lines.size() - 1);
  EXPECT_DOUBLE_EQ(summary.at("events_per_100_frames").get<double>(), 100.0 * (lines.size() - 1) / 5);
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
    EXPECT_EQ(lines[i].at("kind"), "OBJECT_ADDED");
    EXPECT_EQ(lines[i].at("frame"), 3) << "persistence: the third frame that shows it";
    EXPECT_EQ(lines[i].at("source"), after);
    EXPECT_GT(lines[i].at("indices_after").size(), 100u) << "the whole object's points";
  }
  EXPECT_GT(summary.at("median_frame_ms").get<double>(), 0.0);
  // Text: one line per event, then the counts.
  result = cli({"replay", before, after, after, after});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("OBJECT_ADDED"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("4 frames,"), std::string::npos) << result.out;
  // Bad input is named; a frame range beyond the sequence too.
  result = cli({"replay", (tmp_ / "absent").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("absent"), std::string::npos) << result.err;
  result = cli({"replay", (source_dir() / "sample_clouds/tabletop").string() + ":5-9"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("1 frames"), std::string::npos) << result.err;
  result = cli({"replay", before, "--stride", "0"});
  EXPECT_EQ(result.exit_code, 2) << "usage error";
}

TEST_F(CliTest, DiffOfAnMosdPairAndBadInput) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn12.pcd");
  const fs::path learn = data_dir() / "mosd/learn";
  // learn12 -> learn13: same camera; an object is added (and others moved).
  auto result = cli({"diff", (learn / "learn12.pcd").string(), (learn / "learn13.pcd").string(), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json j = parse(result.out);
  EXPECT_EQ(j.at("method"), "same-camera");
  std::size_t added = 0;
  for (const auto& e : j.at("events")) {
    EXPECT_TRUE(e.contains("box_world"));
    for (const char* key : {"indices_before", "indices_after"}) {
      if (!e.contains(key)) continue;
      for (const auto& i : e.at(key)) ASSERT_LT(i.get<int>(), 640 * 480);
    }
    if (e.at("kind") == "OBJECT_ADDED") {
      ++added;
      EXPECT_TRUE(!e.contains("indices_before") || e.at("indices_before").empty());
      EXPECT_GT(e.at("indices_after").size(), 100u);
    }
  }
  EXPECT_GE(added, 1u);
  // The same frame twice: nothing changed.
  const std::string frame = (source_dir() / "sample_clouds/tabletop").string() + ":0";
  result = cli({"diff", frame, frame, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(parse(result.out).at("events").size(), 0u);
  // Bad input is named.
  result = cli({"diff", (learn / "learn12.pcd").string(), (tmp_ / "absent.pcd").string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("absent.pcd"), std::string::npos) << result.err;
  // The mug's PCD VIEWPOINT turns its points behind the camera: no camera can be fitted, and the
  // message says which observation and why.
  result = cli({"diff", (learn / "learn12.pcd").string(), (data_dir() / kMug).string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("AFTER"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("intrinsics"), std::string::npos) << result.err;
}

TEST_F(CliTest, SurpriseFromTheDaemon) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, ""));
  const std::string sequence = (source_dir() / "sample_clouds/tabletop").string();
  auto result = remote({"surprise"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("NOT_FOUND"), std::string::npos) << result.err;
  // The first posed frame becomes a keyframe; the same view again is compared with it.
  ASSERT_EQ(remote({"ingest", sequence}).exit_code, 0);
  ASSERT_EQ(remote({"ingest", sequence}).exit_code, 0);
  result = remote({"surprise", "--json", "--out", (tmp_ / "last.png").string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  json j = parse(result.out);
  EXPECT_GT(j.at("known_pixels").get<std::size_t>(), 10000u);
  EXPECT_EQ(j.at("reference_views"), 1);
  EXPECT_EQ(j.at("regions").size(), 0u) << "the same view again is not surprising";
  EXPECT_TRUE(fs::exists(tmp_ / "last.png"));
  // An observation sent with the call is compared without changing the model.
  result = remote({"surprise", sequence + ":0", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_GT(parse(result.out).at("known_pixels").get<std::size_t>(), 10000u);
  result = remote({"stats", "--json"});
  EXPECT_EQ(parse(result.out).at("frames_processed"), 2);
}

// The CLI sends the token of --token-file (default ~/.scenewatch/token) with the commands that
// change the model; without a readable token file they are refused with a message that says why.
TEST_F(CliTest, CommandsThatChangeTheModelNeedTheTokenFile) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, ""));
  const std::string port = std::to_string(daemon_.port());
  const fs::path missing = tmp_ / "no-such-token";
  auto result = cli({"reset", "--port", port, "--token-file", missing.string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("PERMISSION_DENIED"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find(missing.string()), std::string::npos) << "names the token file it tried: " << result.err;
  result = cli({"save", "--port", port, "--token-file", missing.string()});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("PERMISSION_DENIED"), std::string::npos) << result.err;
  EXPECT_EQ(cli({"health", "--port", port, "--token-file", missing.string()}).exit_code, 0) << "reading needs none";
  EXPECT_EQ(remote({"reset"}).exit_code, 0) << "with the daemon's token file";
}

TEST_F(CliTest, WatchPrintsEventsUntilInterrupted) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  const fs::path learn = data_dir() / "mosd/learn";
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, ""));
  auto watch = ChildProcess::start(
      {cli_binary().string(), "watch", "--json", "--port", std::to_string(daemon_.port())}, tmp_ / "watch.stderr");
  ASSERT_TRUE(watch.has_value());
  // The watcher may subscribe after a frame; repeat the scene from scratch until it reports.
  std::optional<std::string> line;
  for (int attempt = 0; attempt < 20 && !line; ++attempt) {
    ASSERT_EQ(remote({"reset"}).exit_code, 0);
    // An object put on the table (learn12 -> learn13), confirmed on the third frame that shows it.
    const std::string after = (learn / "learn13.pcd").string();
    ASSERT_EQ(remote({"ingest", (learn / "learn12.pcd").string(), after, after, after}).exit_code, 0);
    line = watch->read_line(2.0);
  }
  ASSERT_TRUE(line.has_value()) << watch->stderr_text();
  const json event = parse(*line);
  EXPECT_EQ(event.at("kind"), "OBJECT_ADDED");
  EXPECT_EQ(event.at("level"), "MISMATCH");
  EXPECT_TRUE(event.at("box_world").contains("min")) << "the one JSON form of an event";
  watch->signal(SIGINT);
  EXPECT_EQ(watch->wait(kStartTimeoutS), std::optional<int>(0)) << watch->stderr_text();
}

}  // namespace
}  // namespace scenewatch::test
