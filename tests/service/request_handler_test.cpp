// RequestHandler against a real WorkingMemory: every request goes through the protobuf bytes a
// client would send, and the model must not change when a request is refused.
#include "scenewatch/service/request_handler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>

#include "scenewatch.pb.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/client.h"
#include "test_data.h"

namespace scenewatch::service {
namespace {
namespace fs = std::filesystem;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

/// A flat patch of w x h points 1 m in front of the camera, 1 cm apart.
Frame grid_frame(std::uint32_t w, std::uint32_t h) {
  auto cloud = std::make_shared<Cloud>();
  cloud->width = w;
  cloud->height = h;
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; ++u) {
      PointT p;
      p.x = 0.01f * (static_cast<float>(u) - 0.5f * static_cast<float>(w));
      p.y = 0.01f * (static_cast<float>(v) - 0.5f * static_cast<float>(h));
      p.z = 1.0f;
      p.r = p.g = p.b = 200;
      cloud->points.push_back(p);
    }
  }
  Frame frame;
  frame.cloud = cloud;
  frame.source = "grid";
  return frame;
}

void set_pose(proto::Pose* pose, const Eigen::Matrix4d& m) {
  pose->clear_matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) pose->add_matrix(m(r, c));
  }
}

class RequestHandlerTest : public ::testing::Test {
 protected:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  proto::Response call(RequestHandler& handler, const proto::Request& request) {
    std::string bytes;
    request.SerializeToString(&bytes);
    return parse(handler.handle_now(bytes, context_).payload);
  }

  static proto::Response parse(const std::string& payload) {
    proto::Response response;
    EXPECT_TRUE(response.ParseFromString(payload));
    return response;
  }

  proto::Response ingest(RequestHandler& handler, const proto::IngestFrame& msg) {
    proto::Request request;
    request.set_id(42);
    *request.mutable_ingest_frame() = msg;
    return call(handler, request);
  }

  proto::Response ingest_file(RequestHandler& handler, const std::string& path) {
    proto::Request request;
    request.set_id(43);
    request.mutable_ingest_file()->set_path(path);
    return call(handler, request);
  }

  std::uint64_t frames_processed() const { return memory_.snapshot()->frames_processed; }

  pipeline::WorkingMemory memory_{pipeline::Config{}};
  fs::path tmp_ = test::make_temp_dir("handler");
  SessionContext context_;
};

TEST_F(RequestHandlerTest, HealthEchoesTheRequestId) {
  RequestHandler handler(memory_, {});
  proto::Request request;
  request.set_id(1234);
  request.mutable_health();
  const auto response = call(handler, request);
  EXPECT_EQ(response.id(), 1234u);
  EXPECT_EQ(response.status().code(), proto::Status::OK);
  ASSERT_TRUE(response.has_health());
  EXPECT_FALSE(response.health().version().empty());
}

TEST_F(RequestHandlerTest, UnparseableBytesAreAnInvalidArgument) {
  RequestHandler handler(memory_, {});
  const Reply reply = handler.handle_now(std::string("\xff\xff\xff\xff\x0f", 5), context_);
  EXPECT_FALSE(reply.ok);
  const auto response = parse(reply.payload);
  EXPECT_EQ(response.id(), 0u);
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("not a valid"), std::string::npos) << response.status().message();
}

TEST_F(RequestHandlerTest, EmptyCallIsAnUnknownRequest) {
  RequestHandler handler(memory_, {});
  proto::Request request;
  request.set_id(9);
  const auto response = call(handler, request);
  EXPECT_EQ(response.id(), 9u);
  EXPECT_EQ(response.status().code(), proto::Status::UNKNOWN_REQUEST);
  EXPECT_EQ(response.result_case(), proto::Response::RESULT_NOT_SET);
}

TEST_F(RequestHandlerTest, CallFromANewerClientIsAnUnknownRequest) {
  RequestHandler handler(memory_, {});
  // id = 5 (field 1), then field 99 as a varint: a call this server does not know.
  const std::string bytes("\x08\x05\x98\x06\x01", 5);
  const auto response = parse(handler.handle_now(bytes, context_).payload);
  EXPECT_EQ(response.id(), 5u);
  EXPECT_EQ(response.status().code(), proto::Status::UNKNOWN_REQUEST);
}

TEST_F(RequestHandlerTest, BadCloudSizesAreRefusedAndTheModelIsUnchanged) {
  RequestHandler handler(memory_, {});
  const proto::IngestFrame good = make_ingest_frame(grid_frame(4, 3));

  proto::IngestFrame short_xyz = good;
  short_xyz.mutable_cloud()->mutable_xyz()->pop_back();
  proto::IngestFrame long_xyz = good;
  long_xyz.mutable_cloud()->mutable_xyz()->append(12, '\0');
  proto::IngestFrame wrong_width = good;
  wrong_width.mutable_cloud()->set_width(5);
  proto::IngestFrame empty = good;
  empty.mutable_cloud()->set_width(0);
  proto::IngestFrame bad_rgb = good;
  bad_rgb.mutable_cloud()->mutable_rgb()->resize(5);
  proto::IngestFrame no_cloud = good;
  no_cloud.clear_cloud();
  proto::IngestFrame huge = good;  // 2^32 x 2^32 points must not overflow the size check
  huge.mutable_cloud()->set_width(std::numeric_limits<std::uint32_t>::max());
  huge.mutable_cloud()->set_height(std::numeric_limits<std::uint32_t>::max());

  for (const auto* msg : {&short_xyz, &long_xyz, &wrong_width, &empty, &bad_rgb, &no_cloud, &huge}) {
    const auto response = ingest(handler, *msg);
    EXPECT_EQ(response.id(), 42u);
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT) << response.status().message();
    EXPECT_NE(response.status().message().find("cloud"), std::string::npos) << response.status().message();
    EXPECT_FALSE(response.has_ingest());
  }
  EXPECT_EQ(frames_processed(), 0u);
  // The message says what was expected.
  const auto response = ingest(handler, short_xyz);
  EXPECT_NE(response.status().message().find("143 bytes, expected 144"), std::string::npos)
      << response.status().message();
}

TEST_F(RequestHandlerTest, BadPosesAreRefused) {
  RequestHandler handler(memory_, {});
  const proto::IngestFrame good = make_ingest_frame(grid_frame(4, 3));

  Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
  nan(0, 3) = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix4d scaled = Eigen::Matrix4d::Identity();
  scaled.topLeftCorner<3, 3>() *= 2.0;
  Eigen::Matrix4d reflection = Eigen::Matrix4d::Identity();
  reflection(2, 2) = -1.0;

  for (const auto& [m, expected] : std::vector<std::pair<Eigen::Matrix4d, std::string>>{
           {nan, "non-finite"}, {scaled, "rigid"}, {reflection, "reflection"}}) {
    proto::IngestFrame msg = good;
    set_pose(msg.mutable_pose(), m);
    const auto response = ingest(handler, msg);
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_NE(response.status().message().find("pose"), std::string::npos) << response.status().message();
    EXPECT_NE(response.status().message().find(expected), std::string::npos) << response.status().message();
  }
  proto::IngestFrame fifteen = good;
  set_pose(fifteen.mutable_pose(), Eigen::Matrix4d::Identity());
  fifteen.mutable_pose()->mutable_matrix()->RemoveLast();
  const auto response = ingest(handler, fifteen);
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("16 values"), std::string::npos) << response.status().message();

  proto::IngestFrame nan_stamp = good;
  nan_stamp.set_stamp_s(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ingest(handler, nan_stamp).status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_EQ(frames_processed(), 0u);
}

TEST_F(RequestHandlerTest, IntrinsicsMustFitTheOrganizedCloud) {
  RequestHandler handler(memory_, {});
  Frame frame = grid_frame(4, 3);
  frame.intrinsics = Intrinsics{500, 500, 2, 1.5, 8, 6};
  auto response = ingest(handler, make_ingest_frame(frame));
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("intrinsics"), std::string::npos) << response.status().message();
  frame.intrinsics = Intrinsics{-1, 500, 2, 1.5, 4, 3};
  EXPECT_EQ(ingest(handler, make_ingest_frame(frame)).status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_EQ(frames_processed(), 0u);
}

// IngestFrame.rgbd: the images as a camera gives them, back-projected by the daemon through the
// frame's intrinsics; every inconsistency is refused with the field named, and nothing processed.
TEST_F(RequestHandlerTest, RgbdImagesAreBackProjectedAndBadOnesRefused) {
  RequestHandler handler(memory_, {});
  DepthImage depth;
  depth.width = 60;
  depth.height = 50;
  depth.depth_mm.assign(3000, 1000);
  depth.depth_mm[7] = DepthImage::kInvalid;
  ColorImage color;
  color.width = 60;
  color.height = 50;
  color.rgb.assign(9000, 200);
  Frame meta;
  meta.intrinsics = Intrinsics{500, 500, 29.5, 24.5, 60, 50};
  proto::IngestFrame good = make_ingest_frame(meta);
  set_rgbd_images(depth, &color, &good);

  proto::IngestFrame no_intrinsics = good;
  no_intrinsics.clear_intrinsics();
  proto::IngestFrame wrong_intrinsics = good;
  wrong_intrinsics.mutable_intrinsics()->set_width(61);
  proto::IngestFrame short_depth = good;
  short_depth.mutable_rgbd()->mutable_depth_mm()->pop_back();
  proto::IngestFrame bad_rgb = good;
  bad_rgb.mutable_rgbd()->mutable_rgb()->resize(5);
  proto::IngestFrame zero = good;
  zero.mutable_rgbd()->set_width(0);
  proto::IngestFrame both = good;
  *both.mutable_cloud() = make_ingest_frame(grid_frame(4, 3)).cloud();
  for (const auto& [msg, expected] : std::vector<std::pair<const proto::IngestFrame*, std::string>>{
           {&no_intrinsics, "rgbd needs intrinsics"}, {&wrong_intrinsics, "intrinsics are for a 61 x 50"},
           {&short_depth, "rgbd.depth_mm has 5999 bytes, expected 6000"}, {&bad_rgb, "rgbd.rgb has 5 bytes"},
           {&zero, "rgbd images of 0 x 50"}, {&both, "both cloud and rgbd"}}) {
    const auto response = ingest(handler, *msg);
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT) << expected;
    EXPECT_NE(response.status().message().find(expected), std::string::npos) << response.status().message();
  }
  EXPECT_EQ(frames_processed(), 0u);

  const auto response = ingest(handler, good);
  ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
  EXPECT_EQ(response.ingest().points(), 2999u) << "every pixel with depth is a point";
  EXPECT_EQ(frames_processed(), 1u);
  EXPECT_LT(good.ByteSizeLong(), 5 * 3000 + 100) << "5 bytes a pixel";
}

TEST_F(RequestHandlerTest, ValidFrameIsProcessed) {
  RequestHandler handler(memory_, {});
  Frame frame = grid_frame(60, 50);
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(0.5, 0, 0);
  frame.T_world_camera = pose;
  frame.stamp_s = 3.5;
  const auto response = ingest(handler, make_ingest_frame(frame));
  ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
  ASSERT_TRUE(response.has_ingest());
  EXPECT_EQ(response.ingest().points(), 3000u);
  EXPECT_EQ(frames_processed(), 1u);

  proto::Request request;
  request.mutable_stats();
  const auto stats = call(handler, request);
  ASSERT_TRUE(stats.has_stats());
  EXPECT_EQ(stats.stats().frames_processed(), 1u);
  EXPECT_EQ(stats.stats().points_processed(), 3000u);
}

TEST_F(RequestHandlerTest, GetLocalizationAnswersPerCameraAndRefusesAnUnknownOne) {
  RequestHandler handler(memory_, {});
  const auto where = [&](const std::string& camera, bool only_default = false) {
    proto::Request request;
    request.mutable_get_localization()->set_camera(camera);
    request.mutable_get_localization()->set_only_default(only_default);
    return call(handler, request);
  };
  // Before any frame: no camera at all, and the default camera is not known yet.
  EXPECT_EQ(where("").localization().cameras_size(), 0);
  EXPECT_EQ(where("", true).status().code(), proto::Status::NOT_FOUND);
  Frame frame = grid_frame(60, 50);
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(0.5, 0, 0);
  frame.T_world_camera = pose;
  frame.camera = "arm";
  ASSERT_EQ(ingest(handler, make_ingest_frame(frame)).status().code(), proto::Status::OK);
  const auto arm = where("arm");
  ASSERT_EQ(arm.status().code(), proto::Status::OK) << arm.status().message();
  ASSERT_EQ(arm.localization().cameras_size(), 1);
  EXPECT_EQ(arm.localization().cameras(0).camera(), "arm");
  EXPECT_EQ(arm.localization().cameras(0).state(), "given");  // the default mode
  EXPECT_EQ(arm.localization().cameras(0).t_world_odom().matrix_size(), 16);
  EXPECT_EQ(where("").localization().cameras_size(), 1);
  const auto unknown = where("head");
  EXPECT_EQ(unknown.status().code(), proto::Status::NOT_FOUND);
  EXPECT_NE(unknown.status().message().find("camera 'head'"), std::string::npos) << unknown.status().message();
  EXPECT_NE(unknown.status().message().find("'arm'"), std::string::npos) << unknown.status().message();
}

TEST_F(RequestHandlerTest, LiveFramesAreRecognisedWithoutDecodingAndSkippedUnprocessed) {
  RequestHandler handler(memory_, {});
  proto::Request request;
  request.set_id(77);
  *request.mutable_ingest_frame() = make_ingest_frame(grid_frame(60, 50));
  std::string plain, live;
  request.SerializeToString(&plain);
  request.mutable_ingest_frame()->set_live(true);
  request.SerializeToString(&live);
  EXPECT_FALSE(handler.is_live_frame(plain));
  EXPECT_TRUE(handler.is_live_frame(live));
  EXPECT_FALSE(handler.is_live_frame(live.substr(0, live.size() / 2))) << "truncated";
  EXPECT_FALSE(handler.is_live_frame("garbage bytes"));
  proto::Request health;
  health.mutable_health();
  std::string health_bytes;
  health.SerializeToString(&health_bytes);
  EXPECT_FALSE(handler.is_live_frame(health_bytes));

  const Reply reply = handler.skip_live_frame(live);
  proto::Response response;
  ASSERT_TRUE(response.ParseFromString(reply.payload));
  EXPECT_EQ(response.id(), 77u);
  EXPECT_EQ(response.status().code(), proto::Status::OK);
  EXPECT_TRUE(response.ingest().skipped());
  EXPECT_EQ(response.ingest().frames_skipped(), 1u);
  EXPECT_EQ(frames_processed(), 0u) << "a skipped frame changes nothing";
  proto::Request stats;
  stats.mutable_stats();
  EXPECT_EQ(call(handler, stats).stats().frames_skipped(), 1u);
}

TEST_F(RequestHandlerTest, MosdPairGivesPlanesObjectsAndPushedEvents) {
  // learn12 -> learn13 of mOSD: the same Kinect, unmoved, an object put on the table.
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  RequestHandler handler(memory_, {});
  auto before = io::load_cloud_frame(test::data_dir() / "mosd/learn/learn12.pcd");
  auto after = io::load_cloud_frame(test::data_dir() / "mosd/learn/learn13.pcd");
  ASSERT_TRUE(before.ok() && after.ok());

  std::vector<std::string> pushed;
  context_.event_sink = [&pushed](std::string payload) { pushed.push_back(std::move(payload)); };
  proto::Request subscribe;
  subscribe.set_id(2);
  subscribe.mutable_subscribe();
  const auto subscribed = call(handler, subscribe);
  ASSERT_EQ(subscribed.status().code(), proto::Status::OK);
  EXPECT_EQ(subscribed.subscribe().last_event_id(), 0u);
  EXPECT_GE(context_.subscription, 0);

  const auto first = ingest(handler, make_ingest_frame(*before));
  ASSERT_EQ(first.status().code(), proto::Status::OK) << first.status().message();
  EXPECT_GE(first.ingest().planes_size(), 1);
  EXPECT_GE(first.ingest().clusters_size(), 1);
  EXPECT_EQ(first.ingest().events_size(), 0) << "a first frame reports no change";
  EXPECT_EQ(first.ingest().points(), count_valid(*before->cloud));
  // The new object is confirmed after change.persistence_frames (3) frames that show it.
  int events = 0;
  const std::size_t after_points = count_valid(*after->cloud);
  for (int i = 0; i < 3; ++i) {
    const auto response = ingest(handler, make_ingest_frame(*after));
    ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
    events += response.ingest().events_size();
    // The frame's valid points, every time: not what went into the map (a pending change's
    // points wait), which made the same file report different counts.
    EXPECT_EQ(response.ingest().points(), after_points) << "ingest " << i;
  }
  ASSERT_GE(events, 1);

  // Every event was pushed as a Response with id 0.
  ASSERT_EQ(pushed.size(), static_cast<std::size_t>(events));
  const auto event = parse(pushed.front());
  EXPECT_EQ(event.id(), 0u);
  ASSERT_TRUE(event.has_event());
  EXPECT_EQ(event.event().kind(), proto::Event::OBJECT_ADDED);
  EXPECT_GT(event.event().indices_after_size(), 0) << "the points of the added object in the frame";

  proto::Request objects;
  objects.mutable_get_objects();
  const auto listed = call(handler, objects);
  EXPECT_GE(listed.objects().objects_size(), 1);
  proto::Request planes;
  planes.mutable_get_planes();
  EXPECT_GE(call(handler, planes).planes().planes_size(), 1);
  proto::Request log;
  log.mutable_get_events()->set_since(0);
  EXPECT_EQ(call(handler, log).events().events_size(), events);

  // After unsubscribing nothing more is pushed.
  handler.unsubscribe(context_);
  EXPECT_EQ(context_.subscription, -1);
  proto::Request reset;
  reset.mutable_reset();
  ASSERT_EQ(call(handler, reset).status().code(), proto::Status::OK);
  ASSERT_EQ(ingest(handler, make_ingest_frame(*before)).status().code(), proto::Status::OK);
  for (int i = 0; i < 3; ++i) ASSERT_EQ(ingest(handler, make_ingest_frame(*after)).status().code(), proto::Status::OK);
  EXPECT_EQ(pushed.size(), static_cast<std::size_t>(events));
}

TEST_F(RequestHandlerTest, IngestFileStaysInsideTheDataRoots) {
  const fs::path root = tmp_ / "root";
  const fs::path sibling = tmp_ / "root2";  // shares the prefix "root" but is outside
  fs::create_directories(root / "sub");
  fs::create_directories(sibling);
  std::ofstream(sibling / "x.pcd") << "not a cloud";
  std::ofstream(tmp_ / "outside.pcd") << "not a cloud";
  fs::create_symlink(tmp_ / "outside.pcd", root / "link.pcd");

  {
    RequestHandler no_roots(memory_, {});
    const auto response = ingest_file(no_roots, (root / "sub" / "a.pcd").string());
    EXPECT_EQ(response.status().code(), proto::Status::PERMISSION_DENIED);
    EXPECT_NE(response.status().message().find("data_roots"), std::string::npos) << response.status().message();
  }
  RequestHandler handler(memory_, HandlerConfig{{root}, {}});
  for (const fs::path& outside : {tmp_ / "outside.pcd", sibling / "x.pcd", root / ".." / "outside.pcd",
                                  root / "link.pcd", fs::path("/etc/passwd")}) {
    const auto response = ingest_file(handler, outside.string());
    EXPECT_EQ(response.id(), 43u);
    EXPECT_EQ(response.status().code(), proto::Status::PERMISSION_DENIED) << outside;
    EXPECT_NE(response.status().message().find("outside the data roots"), std::string::npos)
        << response.status().message();
  }
  EXPECT_EQ(ingest_file(handler, "relative/a.pcd").status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_EQ(ingest_file(handler, "").status().code(), proto::Status::INVALID_ARGUMENT);
  const auto missing = ingest_file(handler, (root / "sub" / "missing.pcd").string());
  EXPECT_EQ(missing.status().code(), proto::Status::NOT_FOUND) << missing.status().message();
  EXPECT_NE(missing.status().message().find("missing.pcd"), std::string::npos) << missing.status().message();
  EXPECT_EQ(frames_processed(), 0u);
}

// The file is opened beneath its root by the kernel, after any check: a folder inside the root
// that is (or is swapped for) a symlink to the outside leads nowhere, while a symlink that stays
// inside the root is followed.
TEST_F(RequestHandlerTest, IngestFileOpensBeneathTheRoot) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  const fs::path root = tmp_ / "root";
  const fs::path outside = tmp_ / "elsewhere";
  fs::create_directories(root / "real");
  fs::create_directories(outside);
  fs::copy_file(test::data_dir() / kMug, outside / "mug.pcd");
  fs::copy_file(test::data_dir() / kMug, root / "real" / "mug.pcd");
  fs::create_directory_symlink(outside, root / "swapped");         // a folder swapped for a link out
  fs::create_directory_symlink(root / "real", root / "inside");     // a link that stays inside
  RequestHandler handler(memory_, HandlerConfig{{root}, {}});
  const auto escaped = ingest_file(handler, (root / "swapped" / "mug.pcd").string());
  EXPECT_EQ(escaped.status().code(), proto::Status::PERMISSION_DENIED) << escaped.status().message();
  EXPECT_EQ(frames_processed(), 0u);
  const auto inside = ingest_file(handler, (root / "inside" / "mug.pcd").string());
  ASSERT_EQ(inside.status().code(), proto::Status::OK) << inside.status().message();
  EXPECT_EQ(frames_processed(), 1u);
  const auto folder = ingest_file(handler, (root / "real").string());
  EXPECT_EQ(folder.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(folder.status().message().find("not a regular file"), std::string::npos) << folder.status().message();
}

TEST_F(RequestHandlerTest, IngestFileReadsACloudUnderARoot) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  RequestHandler handler(memory_, HandlerConfig{{test::data_dir() / "pcl"}, {}});
  const auto response = ingest_file(handler, (test::data_dir() / "pcl" / ".." / kMug).string());
  ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
  EXPECT_GE(response.ingest().planes_size(), 1);
  EXPECT_EQ(frames_processed(), 1u);
}

TEST_F(RequestHandlerTest, IngestFileRefusesFilesOverTheSizeLimitUnread) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  const fs::path mug = test::data_dir() / kMug;
  RequestHandler handler(memory_, HandlerConfig{{test::data_dir() / "pcl"}, {}, fs::file_size(mug) - 1});
  const auto response = ingest_file(handler, mug.string());
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("max_file_bytes"), std::string::npos) << response.status().message();
  EXPECT_EQ(frames_processed(), 0u);
  RequestHandler roomy(memory_, HandlerConfig{{test::data_dir() / "pcl"}, {}, fs::file_size(mug)});
  EXPECT_EQ(ingest_file(roomy, mug.string()).status().code(), proto::Status::OK) << "a file at the limit is read";
}

TEST_F(RequestHandlerTest, OccupancyQueriesAreValidated) {
  RequestHandler handler(memory_, {});
  proto::Request request;
  request.mutable_query_occupancy();
  EXPECT_EQ(call(handler, request).status().code(), proto::Status::INVALID_ARGUMENT);

  auto* p = request.mutable_query_occupancy()->add_points();
  p->set_x(std::numeric_limits<double>::infinity());
  auto response = call(handler, request);
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("points[0]"), std::string::npos) << response.status().message();

  p->set_x(0.0);
  auto* box = request.mutable_query_occupancy()->mutable_box();
  box->mutable_min()->set_x(1.0);  // min.x > max.x
  response = call(handler, request);
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(response.status().message().find("box"), std::string::npos) << response.status().message();

  box->mutable_max()->set_x(2.0);
  box->mutable_max()->set_y(1.0);
  box->mutable_max()->set_z(1.0);
  request.mutable_query_occupancy()->add_points()->set_z(1.0);
  response = call(handler, request);
  ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
  EXPECT_EQ(response.occupancy().states_size(), 2);
  EXPECT_EQ(response.occupancy().states(0), proto::OCCUPANCY_UNKNOWN);  // empty map
  ASSERT_TRUE(response.occupancy().has_box());
  EXPECT_EQ(response.occupancy().box().state(), proto::OCCUPANCY_UNKNOWN);

  proto::Request clear;
  clear.mutable_clear_box();
  EXPECT_EQ(call(handler, clear).status().code(), proto::Status::INVALID_ARGUMENT);
}

TEST_F(RequestHandlerTest, SaveAndLoadUseTheConfiguredModelDirectory) {
  {
    RequestHandler no_dir(memory_, {});
    proto::Request save;
    save.mutable_save_model();
    const auto response = call(no_dir, save);
    EXPECT_EQ(response.status().code(), proto::Status::UNAVAILABLE);
    EXPECT_NE(response.status().message().find("model_dir"), std::string::npos) << response.status().message();
  }
  const fs::path model = tmp_ / "model";
  RequestHandler handler(memory_, HandlerConfig{{}, model});
  proto::Request load;
  load.mutable_load_model();
  EXPECT_EQ(call(handler, load).status().code(), proto::Status::NOT_FOUND);

  ASSERT_EQ(ingest(handler, make_ingest_frame(grid_frame(30, 30))).status().code(), proto::Status::OK);
  proto::Request save;
  save.mutable_save_model();
  const auto saved = call(handler, save);
  ASSERT_EQ(saved.status().code(), proto::Status::OK) << saved.status().message();
  EXPECT_EQ(saved.save_model().model_dir(), model.string());

  proto::Request reset;
  reset.mutable_reset();
  ASSERT_EQ(call(handler, reset).status().code(), proto::Status::OK);
  EXPECT_EQ(frames_processed(), 0u);
  const auto loaded = call(handler, load);
  ASSERT_EQ(loaded.status().code(), proto::Status::OK) << loaded.status().message();
  EXPECT_EQ(frames_processed(), 1u);
}

TEST_F(RequestHandlerTest, ModelChangesRunOnTheMutateExecutor) {
  std::deque<std::function<void()>> mutate_queue, query_queue;
  RequestHandler handler(
      memory_, {}, [&](std::function<void()> task) { mutate_queue.push_back(std::move(task)); },
      [&](std::function<void()> task) { query_queue.push_back(std::move(task)); });
  std::vector<Reply> replies;
  auto done = [&replies](Reply reply) { replies.push_back(std::move(reply)); };

  proto::Request request;
  request.set_id(1);
  *request.mutable_ingest_frame() = make_ingest_frame(grid_frame(10, 10));
  handler.handle(request.SerializeAsString(), context_, done);
  EXPECT_TRUE(replies.empty());
  ASSERT_EQ(mutate_queue.size(), 1u);

  request.Clear();
  request.set_id(2);
  request.mutable_health();
  handler.handle(request.SerializeAsString(), context_, done);  // answered at once
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(parse(replies[0].payload).id(), 2u);

  request.Clear();
  request.set_id(3);
  request.mutable_stats();
  handler.handle(request.SerializeAsString(), context_, done);
  ASSERT_EQ(query_queue.size(), 1u);

  mutate_queue.front()();
  query_queue.front()();
  ASSERT_EQ(replies.size(), 3u);
  EXPECT_EQ(parse(replies[1].payload).id(), 1u);
  EXPECT_EQ(parse(replies[1].payload).status().code(), proto::Status::OK);
  EXPECT_EQ(replies[1].call, "ingest_frame");
  EXPECT_EQ(parse(replies[2].payload).stats().frames_processed(), 1u);
}

TEST_F(RequestHandlerTest, AfterShutdownModelChangesAreRefused) {
  RequestHandler handler(memory_, {});
  handler.shutdown();
  const auto response = ingest(handler, make_ingest_frame(grid_frame(10, 10)));
  EXPECT_EQ(response.status().code(), proto::Status::UNAVAILABLE);
  EXPECT_EQ(frames_processed(), 0u);
  proto::Request health;
  health.mutable_health();
  EXPECT_EQ(call(handler, health).status().code(), proto::Status::OK);
}

TEST_F(RequestHandlerTest, CallsThatChangeTheModelNeedTheToken) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  HandlerConfig config;
  config.model_dir = tmp_ / "model";
  config.token = token;
  RequestHandler handler(memory_, config);
  ASSERT_EQ(ingest(handler, make_ingest_frame(grid_frame(4, 3))).status().code(), proto::Status::PERMISSION_DENIED);
  EXPECT_EQ(frames_processed(), 0u);

  // With the token a frame goes in; then every call that changes the model is refused without it,
  // or with a wrong one (also one that is a prefix of it), and the model stays as it was.
  proto::Request first;
  first.set_token(token);
  *first.mutable_ingest_frame() = make_ingest_frame(grid_frame(4, 3));
  ASSERT_EQ(call(handler, first).status().code(), proto::Status::OK);
  ASSERT_EQ(frames_processed(), 1u);
  std::vector<proto::Request> changes(6);
  *changes[0].mutable_ingest_frame() = make_ingest_frame(grid_frame(4, 3));
  changes[1].mutable_ingest_file()->set_path("/etc/passwd");
  auto* box = changes[2].mutable_clear_box()->mutable_box();
  box->mutable_min()->set_x(-5), box->mutable_min()->set_y(-5), box->mutable_min()->set_z(-5);
  box->mutable_max()->set_x(5), box->mutable_max()->set_y(5), box->mutable_max()->set_z(5);
  changes[3].mutable_reset();
  changes[4].mutable_save_model();
  changes[5].mutable_load_model();
  for (const std::string& wrong : {std::string(), token.substr(0, 31), token + "0", std::string(32, '0')}) {
    for (auto request : changes) {
      request.set_id(7);
      request.set_token(wrong);
      const auto response = call(handler, request);
      EXPECT_EQ(response.id(), 7u);
      EXPECT_EQ(response.status().code(), proto::Status::PERMISSION_DENIED) << request.ShortDebugString();
      EXPECT_NE(response.status().message().find("token"), std::string::npos) << response.status().message();
      EXPECT_NE(response.status().message().find(wrong.empty() ? "carries none" : "is wrong"), std::string::npos)
          << response.status().message();
      EXPECT_FALSE(response.has_reset() || response.has_ingest() || response.has_save_model());
    }
  }
  EXPECT_EQ(frames_processed(), 1u);
  EXPECT_FALSE(fs::exists(tmp_ / "model")) << "SaveModel ran without the token";

  // Read-only calls need no token.
  proto::Request objects;
  objects.mutable_get_objects();
  const auto listed = call(handler, objects);
  EXPECT_EQ(listed.status().code(), proto::Status::OK);
  EXPECT_EQ(listed.objects().frames_processed(), 1u);
  proto::Request occupancy;
  occupancy.mutable_query_occupancy()->add_points()->set_z(1.0);
  EXPECT_EQ(call(handler, occupancy).status().code(), proto::Status::OK);

  // And with it, Reset forgets the frame.
  proto::Request reset;
  reset.set_token(token);
  reset.mutable_reset();
  EXPECT_EQ(call(handler, reset).status().code(), proto::Status::OK);
  EXPECT_EQ(frames_processed(), 0u);
}

TEST_F(RequestHandlerTest, ConnectionErrorPayloadHasNoId) {
  RequestHandler handler(memory_, {});
  const auto response = parse(handler.error_payload(ErrorCode::kInvalidArgument, "broken framing"));
  EXPECT_EQ(response.id(), 0u);
  EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_EQ(response.status().message(), "broken framing");
}

// DefineClass changes the model's classes: it needs the token; the classes it defines are listed
// by ListClasses (no token) and kept in ontology.sqlite across a restart (a new catalog).
TEST_F(RequestHandlerTest, DefineAndListClasses) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  const fs::path store = tmp_ / "ontology.sqlite";
  auto catalog = ontology::ClassCatalog::open(test::source_dir() / "config/ontology.yaml", store);
  ASSERT_TRUE(catalog.ok()) << catalog.error().message;
  HandlerConfig config;
  config.token = token;
  config.classes = std::move(*catalog);
  RequestHandler handler(memory_, config);

  proto::Request list;
  list.mutable_list_classes();
  auto listed = call(handler, list);
  ASSERT_EQ(listed.status().code(), proto::Status::OK) << listed.status().message();
  ASSERT_EQ(listed.list_classes().classes_size(), 5);
  EXPECT_EQ(listed.list_classes().classes(1).name(), "cup");
  EXPECT_EQ(listed.list_classes().classes(1).shape(), "frustum");
  EXPECT_DOUBLE_EQ(listed.list_classes().classes(1).radius_m().max(), 0.07);
  EXPECT_NE(listed.list_classes().yaml().find("name: cup"), std::string::npos);

  proto::Request define;
  define.set_id(9);
  define.mutable_define_class()->set_yaml(
      "classes:\n  - {name: kettle, shape: cylinder, radius_m: [0.06, 0.12], height_m: [0.12, 0.3], top: closed}\n");
  auto refused = call(handler, define);
  EXPECT_EQ(refused.status().code(), proto::Status::PERMISSION_DENIED);
  define.set_token(token);
  auto defined = call(handler, define);
  ASSERT_EQ(defined.status().code(), proto::Status::OK) << defined.status().message();
  ASSERT_EQ(defined.define_class().defined_size(), 1);
  EXPECT_EQ(defined.define_class().defined(0), "kettle");
  EXPECT_TRUE(defined.define_class().persisted());
  EXPECT_EQ(call(handler, list).list_classes().classes_size(), 6);

  // A bad class is refused with its field named, and nothing changes.
  define.mutable_define_class()->set_yaml("classes:\n  - {name: pot, shape: cylinder, radius_m: [0.2, 0.1], height_m: [0.1, 0.2]}\n");
  auto bad = call(handler, define);
  EXPECT_EQ(bad.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(bad.status().message().find("radius_m"), std::string::npos) << bad.status().message();
  EXPECT_EQ(call(handler, list).list_classes().classes_size(), 6);

  auto reopened = ontology::ClassCatalog::open(test::source_dir() / "config/ontology.yaml", store);
  ASSERT_TRUE(reopened.ok());
  EXPECT_NE((*reopened)->library().find("kettle"), nullptr);

  // Without classes the calls say so.
  RequestHandler bare(memory_, HandlerConfig{});
  EXPECT_EQ(call(bare, list).status().code(), proto::Status::UNAVAILABLE);
}

}  // namespace
}  // namespace scenewatch::service
