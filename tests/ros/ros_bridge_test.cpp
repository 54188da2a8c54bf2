// scenewatch-ros (issue 32) end to end, no mocks: the real scenewatchd on loopback, the real
// bridge started as a user starts it, and a DDS participant of the test that is a ROS 2 peer. It
// publishes the simulator's cup_added (320x240 RGB-D, a hand-held camera, 12 frames per phase) as
// a camera driver does (sensor_msgs/Image rgb8 + 16UC1, CameraInfo) with the camera pose on /tf
// under a /tf_static link, and receives what the bridge publishes: the change's one event, the
// objects as vision_msgs/Detection3DArray and the map as octomap_msgs/Octomap, checked against the
// daemon's own answers and its saved map read back by OctoMap.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <cmath>
#include <cstring>

#include "daemon_harness.h"
#include "dds_peer.h"
#include "scenewatch/io/rgbd.h"
#include "shipped_scenario.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

fs::path bridge_binary() { return binary_dir() / "apps" / "scenewatch-ros" / "scenewatch-ros"; }
fs::path stalled_subscriber_binary() { return binary_dir() / "tests" / "ros" / "stalled_subscriber"; }

constexpr double kStamp0 = 1700000000.0;   ///< ROS time of the first frame (epoch seconds, as a driver stamps)
constexpr double kFrameWaitS = 15.0;       ///< bounds a hung test only

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

geometry_msgs_msg_dds__TransformStamped_ transform(const Pose& T, double stamp_s, const char* parent, const char* child) {
  geometry_msgs_msg_dds__TransformStamped_ t{};
  t.header.stamp = ros::ros_time(stamp_s);
  t.header.frame_id = const_cast<char*>(parent);
  t.child_frame_id = const_cast<char*>(child);
  const Eigen::Quaterniond q(T.linear());
  t.transform.translation = {T.translation().x(), T.translation().y(), T.translation().z()};
  t.transform.rotation = {q.x(), q.y(), q.z(), q.w()};
  return t;
}

sensor_msgs_msg_dds__Image_ image(double stamp_s, int width, int height, const char* encoding, std::uint32_t step, std::uint8_t* data,
                                  std::size_t size) {
  sensor_msgs_msg_dds__Image_ m{};
  m.header.stamp = ros::ros_time(stamp_s);
  m.header.frame_id = const_cast<char*>("camera_optical");
  m.width = static_cast<std::uint32_t>(width);
  m.height = static_cast<std::uint32_t>(height);
  m.encoding = const_cast<char*>(encoding);
  m.step = step;
  m.data._length = m.data._maximum = static_cast<std::uint32_t>(size);
  m.data._buffer = data;
  return m;
}

/// One visualization_msgs/Marker as received, copied out of its sample.
struct ReceivedMarker {
  std::string frame_id, ns, text;
  double stamp_s = 0;
  std::int32_t id = 0, type = 0, action = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), scale = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::vector<Eigen::Vector3d> points;
};

ReceivedMarker received_marker(const visualization_msgs_msg_dds__Marker_& m) {
  ReceivedMarker r;
  r.frame_id = m.header.frame_id;
  r.stamp_s = ros::seconds(m.header.stamp);
  r.ns = m.ns;
  r.text = m.text;
  r.id = m.id;
  r.type = m.type;
  r.action = m.action;
  r.position = Eigen::Vector3d(m.pose.position.x, m.pose.position.y, m.pose.position.z);
  r.orientation = Eigen::Quaterniond(m.pose.orientation.w, m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z);
  r.scale = Eigen::Vector3d(m.scale.x, m.scale.y, m.scale.z);
  for (std::uint32_t i = 0; i < m.points._length; ++i) {
    r.points.emplace_back(m.points._buffer[i].x, m.points._buffer[i].y, m.points._buffer[i].z);
  }
  return r;
}

/// The test's ROS 2 side: a camera driver (depth 16UC1 + rgb8 + CameraInfo), TF (world -> rig on
/// /tf_static, rig -> camera_optical on /tf per frame) and a subscriber of the bridge's topics.
class CameraPeer {
 public:
  /// `root_frame`: the parent of the rig's /tf_static link (the world, or the robot's odometry).
  explicit CameraPeer(std::uint32_t domain, std::string root_frame = "world") : peer_(domain), root_frame_(std::move(root_frame)) {
    depth_w_ = peer_.entity("/camera/depth/image_rect_raw", &sensor_msgs_msg_dds__Image__desc, false, false, 5);
    color_w_ = peer_.entity("/camera/color/image_raw", &sensor_msgs_msg_dds__Image__desc, false, false, 5);
    info_w_ = peer_.entity("/camera/depth/camera_info", &sensor_msgs_msg_dds__CameraInfo__desc, false, false, 5);
    // Reliable, as a node on ROS 2's default QoS publishes it: a 1.2 MB best-effort sample is lost
    // whole when one of its UDP fragments overflows the receive buffer (the bridge's reader is
    // best effort and takes either).
    cloud_w_ = peer_.entity("/camera/depth/points", &sensor_msgs_msg_dds__PointCloud2__desc, false, true, 5);
    tf_w_ = peer_.entity("/tf", &tf2_msgs_msg_dds__TFMessage__desc, false, true, 100);
    tf_static_w_ = peer_.entity("/tf_static", &tf2_msgs_msg_dds__TFMessage__desc, false, true, 1, true);
    events_r_ = peer_.entity("/scenewatch/events", &scenewatch_msgs_msg_dds__EventArray__desc, true, true, 100);
    objects_r_ = peer_.entity("/scenewatch/objects", &vision_msgs_msg_dds__Detection3DArray__desc, true, true, 100);
    map_r_ = peer_.entity("/scenewatch/octomap_binary", &octomap_msgs_msg_dds__Octomap__desc, true, true, 1, true);
    markers_r_ = peer_.entity("/scenewatch/markers", &visualization_msgs_msg_dds__MarkerArray__desc, true, true, 100);
    // Best effort, as the bridge writes it (a reliable reader would not match a best-effort writer).
    surprise_r_ = peer_.entity("/scenewatch/surprise", &sensor_msgs_msg_dds__Image__desc, true, false, 100);
    // world -> rig: fixed and not the identity, so the bridge must chain a static and a timed link.
    T_world_rig_.translation() = Eigen::Vector3d(0.3, -0.2, 0.1);
    T_world_rig_.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }

  /// Waits for the bridge's participant (every writer and reader matched; the markers reader only
  /// when `markers`; the cloud writer instead of the images' when `cloud`), then sends /tf_static.
  bool connect(double timeout_s, bool markers = true, bool cloud = false) {
    std::vector<dds_entity_t> readers{events_r_, objects_r_, map_r_};
    if (markers) readers.push_back(markers_r_), readers.push_back(surprise_r_);
    const std::vector<dds_entity_t> writers =
        cloud ? std::vector<dds_entity_t>{cloud_w_, info_w_, tf_w_, tf_static_w_} : std::vector<dds_entity_t>{depth_w_, color_w_, info_w_, tf_w_, tf_static_w_};
    if (!DdsPeer::wait_matched(writers, readers, timeout_s)) return false;
    auto t = transform(T_world_rig_, kStamp0, root_frame_.c_str(), "rig");
    tf2_msgs_msg_dds__TFMessage_ m{};
    m.transforms._length = m.transforms._maximum = 1;
    m.transforms._buffer = &t;
    return dds_write(tf_static_w_, &m) == DDS_RETCODE_OK;
  }

  /// The frame's TF: rig -> camera_optical at `stamp`.
  void publish_tf(const sim::SimFrame& rendered, double stamp, const Pose& T_drift = Pose::Identity()) {
    const Pose T_rig_camera = T_world_rig_.inverse() * T_drift * rendered.truth.T_world_camera_reported;
    auto tf = transform(T_rig_camera, stamp, "rig", "camera_optical");
    tf2_msgs_msg_dds__TFMessage_ tf_message{};
    tf_message.transforms._length = tf_message.transforms._maximum = 1;
    tf_message.transforms._buffer = &tf;
    EXPECT_EQ(dds_write(tf_w_, &tf_message), DDS_RETCODE_OK);
  }

  /// Publishes one frame as an organized PointCloud2 (x, y, z, rgb as FLOAT32, 16 bytes a point;
  /// NaN where there is no depth, as the depth_image_proc nodes do) with its TF, and no CameraInfo.
  void publish_cloud(const sim::SimFrame& rendered, const Intrinsics& K, double stamp) {
    auto points = io::rgbd_to_cloud(rendered.color, rendered.depth, K);
    ASSERT_TRUE(points.ok()) << points.error().message;
    std::vector<std::uint8_t> data((*points)->size() * 16);
    for (std::size_t i = 0; i < (*points)->size(); ++i) {
      const auto& p = (**points)[i];
      const float xyz[3] = {p.x, p.y, p.z};
      const std::uint32_t rgb = (std::uint32_t{p.r} << 16) | (std::uint32_t{p.g} << 8) | p.b;
      std::memcpy(&data[16 * i], xyz, 12);
      std::memcpy(&data[16 * i + 12], &rgb, 4);
    }
    sensor_msgs_msg_dds__PointField_ fields[4] = {{const_cast<char*>("x"), 0, 7, 1}, {const_cast<char*>("y"), 4, 7, 1},
                                                  {const_cast<char*>("z"), 8, 7, 1}, {const_cast<char*>("rgb"), 12, 7, 1}};
    sensor_msgs_msg_dds__PointCloud2_ m{};
    m.header.stamp = ros::ros_time(stamp);
    m.header.frame_id = const_cast<char*>("camera_optical");
    m.width = static_cast<std::uint32_t>(K.width);
    m.height = static_cast<std::uint32_t>(K.height);
    m.fields._length = m.fields._maximum = 4;
    m.fields._buffer = fields;
    m.point_step = 16;
    m.row_step = 16 * m.width;
    m.data._length = m.data._maximum = static_cast<std::uint32_t>(data.size());
    m.data._buffer = data.data();
    publish_tf(rendered, stamp);
    EXPECT_EQ(dds_write(cloud_w_, &m), DDS_RETCODE_OK);
  }

  /// Publishes one frame as a driver does: TF (unless `with_tf` is false), CameraInfo, colour, depth.
  /// `T_drift`: an error of the pose source (odometry), applied to the reported pose.
  void publish(const sim::SimFrame& rendered, const Intrinsics& K, double stamp, bool with_tf = true, const Pose& T_drift = Pose::Identity()) {
    std::vector<std::uint8_t> rgb = rendered.color.rgb;
    std::vector<std::uint8_t> depth(rendered.depth.depth_mm.size() * 2);
    std::memcpy(depth.data(), rendered.depth.depth_mm.data(), depth.size());  // 16UC1, little-endian like the host
    sensor_msgs_msg_dds__CameraInfo_ info{};
    info.header.stamp = ros::ros_time(stamp);
    info.header.frame_id = const_cast<char*>("camera_optical");
    info.width = static_cast<std::uint32_t>(K.width);
    info.height = static_cast<std::uint32_t>(K.height);
    info.distortion_model = const_cast<char*>("plumb_bob");
    const double k[9] = {K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1};
    std::copy(k, k + 9, info.k);
    info.r[0] = info.r[4] = info.r[8] = 1;
    const double p[12] = {K.fx, 0, K.cx, 0, 0, K.fy, K.cy, 0, 0, 0, 1, 0};
    std::copy(p, p + 12, info.p);
    auto color_message = image(stamp, K.width, K.height, "rgb8", static_cast<std::uint32_t>(3 * K.width), rgb.data(), rgb.size());
    auto depth_message = image(stamp, K.width, K.height, "16UC1", static_cast<std::uint32_t>(2 * K.width), depth.data(), depth.size());
    if (with_tf) publish_tf(rendered, stamp, T_drift);
    EXPECT_EQ(dds_write(info_w_, &info), DDS_RETCODE_OK);
    EXPECT_EQ(dds_write(color_w_, &color_message), DDS_RETCODE_OK);
    EXPECT_EQ(dds_write(depth_w_, &depth_message), DDS_RETCODE_OK);
  }

  /// The Detection3DArray of the frame stamped `stamp`, waiting at most timeout_s: its objects' ids
  /// and box centres (nothing on timeout).
  std::optional<std::vector<std::pair<std::string, Eigen::Vector3d>>> objects_of(double stamp, double timeout_s) {
    std::optional<std::vector<std::pair<std::string, Eigen::Vector3d>>> out;
    const auto start = Clock::now();
    while (!out && ms_since(start) < timeout_s * 1000) {
      DdsPeer::take<vision_msgs_msg_dds__Detection3DArray_>(objects_r_, [&](const vision_msgs_msg_dds__Detection3DArray_& m) {
        if (std::abs(ros::seconds(m.header.stamp) - stamp) > 1e-6) return;
        out.emplace();
        for (std::uint32_t i = 0; i < m.detections._length; ++i) {
          const auto& d = m.detections._buffer[i];
          EXPECT_STREQ(d.header.frame_id, "world");
          EXPECT_EQ(d.results._length, 1u);
          out->emplace_back(d.id, Eigen::Vector3d(d.bbox.center.position.x, d.bbox.center.position.y, d.bbox.center.position.z));
        }
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return out;
  }

  /// The MarkerArray of the frame stamped `stamp` (its first marker's stamp), waiting at most
  /// timeout_s (nothing on timeout).
  std::optional<std::vector<ReceivedMarker>> markers_of(double stamp, double timeout_s) {
    std::optional<std::vector<ReceivedMarker>> out;
    const auto start = Clock::now();
    while (!out && ms_since(start) < timeout_s * 1000) {
      DdsPeer::take<visualization_msgs_msg_dds__MarkerArray_>(markers_r_, [&](const visualization_msgs_msg_dds__MarkerArray_& m) {
        if (m.markers._length == 0 || std::abs(ros::seconds(m.markers._buffer[0].header.stamp) - stamp) > 1e-6) return;
        out.emplace();
        for (std::uint32_t i = 0; i < m.markers._length; ++i) out->push_back(received_marker(m.markers._buffer[i]));
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return out;
  }

  /// A surprise heatmap as received: its header, layout and pixel bytes.
  struct Heatmap {
    double stamp_s = 0;
    std::string frame_id, encoding;
    std::uint32_t width = 0, height = 0, step = 0;
    std::uint8_t is_bigendian = 1;
    std::string data;
  };
  /// Every heatmap that has arrived, until the one stamped `last_stamp` or timeout_s.
  std::vector<Heatmap> heatmaps_until(double last_stamp, double timeout_s) {
    std::vector<Heatmap> out;
    const auto start = Clock::now();
    while ((out.empty() || std::abs(out.back().stamp_s - last_stamp) > 1e-6) && ms_since(start) < timeout_s * 1000) {
      DdsPeer::take<sensor_msgs_msg_dds__Image_>(surprise_r_, [&](const sensor_msgs_msg_dds__Image_& m) {
        out.push_back({ros::seconds(m.header.stamp), m.header.frame_id ? m.header.frame_id : "", m.encoding ? m.encoding : "", m.width,
                       m.height, m.step, m.is_bigendian, std::string(reinterpret_cast<const char*>(m.data._buffer), m.data._length)});
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return out;
  }

  dds_entity_t events_reader() const { return events_r_; }
  dds_entity_t markers_reader() const { return markers_r_; }
  dds_entity_t surprise_reader() const { return surprise_r_; }
  dds_entity_t map_reader() const { return map_r_; }

 private:
  DdsPeer peer_;
  std::string root_frame_;
  dds_entity_t depth_w_ = 0, color_w_ = 0, info_w_ = 0, cloud_w_ = 0, tf_w_ = 0, tf_static_w_ = 0, events_r_ = 0, objects_r_ = 0, map_r_ = 0,
               markers_r_ = 0, surprise_r_ = 0;
  Pose T_world_rig_ = Pose::Identity();
};

/// An event as the EventArray gave it: what its marker must show.
struct ReceivedEvent {
  std::uint64_t id = 0;
  double stamp_s = 0;
  Eigen::Vector3d box_min, box_max;
};

/// The frame's markers of namespace `ns` (and `type`).
std::vector<const ReceivedMarker*> markers_in(const std::vector<ReceivedMarker>& array, const std::string& ns, std::int32_t type) {
  std::vector<const ReceivedMarker*> out;
  for (const auto& m : array) {
    if (m.ns == ns && m.type == type && m.action == visualization_msgs_msg_dds__Marker_Constants_ADD) out.push_back(&m);
  }
  return out;
}

/// The MarkerArrays of the cup test against the daemon's objects, the event and the simulator's
/// truth (the cup's centre, the table's height).
void expect_markers(const std::vector<std::pair<double, std::vector<ReceivedMarker>>>& arrays,
                    const google::protobuf::RepeatedPtrField<proto::Object>& objects, const ReceivedEvent& event,
                    const Eigen::Vector3d& cup_center, double table_height_m) {
  ASSERT_FALSE(arrays.empty());
  // Every array: a DELETEALL first, then markers in the world frame stamped with their frame's stamp.
  for (const auto& [stamp, array] : arrays) {
    ASSERT_FALSE(array.empty());
    EXPECT_EQ(array.front().action, visualization_msgs_msg_dds__Marker_Constants_DELETEALL);
    for (const auto& m : array) {
      EXPECT_EQ(m.frame_id, "world");
      EXPECT_NEAR(m.stamp_s, stamp, 1e-6);
    }
  }
  const auto& last = arrays.back().second;

  // Objects: one CUBE per object, its pose and scale the daemon's box; one near the cup's centre.
  const auto cubes = markers_in(last, "objects", visualization_msgs_msg_dds__Marker_Constants_CUBE);
  ASSERT_EQ(cubes.size(), static_cast<std::size_t>(objects.size()));
  double cup_distance = 1e9;
  const ReceivedMarker* cup_cube = nullptr;
  for (int i = 0; i < objects.size(); ++i) {
    const proto::OrientedBox& box = objects[i].box();
    const ReceivedMarker& m = *cubes[static_cast<std::size_t>(i)];
    EXPECT_EQ(m.id, static_cast<std::int32_t>(objects[i].id()));
    EXPECT_LT((m.position - Eigen::Vector3d(box.center().x(), box.center().y(), box.center().z())).norm(), 1e-9);
    EXPECT_LT((m.scale - Eigen::Vector3d(box.extents().x(), box.extents().y(), box.extents().z())).norm(), 1e-9);
    EXPECT_NEAR(m.orientation.norm(), 1.0, 1e-6);
    if ((m.position - cup_center).norm() < cup_distance) {
      cup_distance = (m.position - cup_center).norm();
      cup_cube = &m;
    }
  }
  ASSERT_NE(cup_cube, nullptr);
  // Measured 7 mm (the box of the points seen from one side); issue 32 allows 3 cm.
  EXPECT_LT(cup_distance, 0.015) << "no object box within 1.5 cm of the cup's centre";
  // Its label: above the box, "#<id>".
  bool labelled = false;
  for (const auto* label : markers_in(last, "labels", visualization_msgs_msg_dds__Marker_Constants_TEXT_VIEW_FACING)) {
    if (label->id != cup_cube->id) continue;
    labelled = true;
    EXPECT_EQ(label->text.rfind("#" + std::to_string(cup_cube->id), 0), 0u) << label->text;
    EXPECT_GT(label->position.z(), cup_cube->position.z());
  }
  EXPECT_TRUE(labelled) << "no label of the cup's box";

  // Planes: a closed hull on the table top.
  double worst_table_z = 1e9;
  for (const auto* strip : markers_in(last, "planes", visualization_msgs_msg_dds__Marker_Constants_LINE_STRIP)) {
    if (strip->points.size() < 4) continue;
    double worst = 0;
    for (const auto& p : strip->points) worst = std::max(worst, std::abs(p.z() - table_height_m));
    worst_table_z = std::min(worst_table_z, worst);
    EXPECT_LT((strip->points.front() - strip->points.back()).norm(), 1e-12) << "the hull is closed";
  }
  // Measured 0.1 mm: the hull lies on the fitted plane, so this is the fit's offset, well inside
  // the depth noise at the table's 1 to 1.5 m (1.4 mm x z^2); issue 32 allows 1 cm.
  EXPECT_LT(worst_table_z, 0.003) << "no plane hull within 3 mm of the table top (z = " << table_height_m << " m)";

  // The event: a yellow wireframe of its box from the array of the frame that raised it on.
  std::size_t first_with_event = arrays.size();
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    const auto lists = markers_in(arrays[i].second, "events", visualization_msgs_msg_dds__Marker_Constants_LINE_LIST);
    const auto it = std::find_if(lists.begin(), lists.end(), [&](const ReceivedMarker* m) { return m->id == static_cast<std::int32_t>(event.id); });
    if (it == lists.end()) {
      EXPECT_EQ(first_with_event, arrays.size()) << "the event's marker vanished from the frame of " << arrays[i].first - kStamp0 << " s";
      continue;
    }
    if (first_with_event == arrays.size()) first_with_event = i;
    ASSERT_EQ((*it)->points.size(), 24u) << "12 edges";
    Eigen::Vector3d lo = (*it)->points[0], hi = (*it)->points[0];
    for (const auto& p : (*it)->points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    EXPECT_LT((lo - event.box_min).norm() + (hi - event.box_max).norm(), 1e-9);
  }
  ASSERT_LT(first_with_event, arrays.size()) << "no events marker after the event";
  EXPECT_NEAR(arrays[first_with_event].first, event.stamp_s, 1e-6) << "the event's marker comes with the frame that raised it";
  std::printf("markers of the last frame: %zu (%zu plane hulls, %zu boxes); cup box %.1f mm from the cup's centre; plane hull within %.1f mm of the table top; "
              "event %llu drawn from frame %zu of %zu on\n",
              last.size(), markers_in(last, "planes", visualization_msgs_msg_dds__Marker_Constants_LINE_STRIP).size(), cubes.size(),
              cup_distance * 1000, worst_table_z * 1000, static_cast<unsigned long long>(event.id), first_with_event + 1,
              arrays.size());
}

class RosBridgeTest : public ::testing::Test {
 protected:
  void TearDown() override {
    if (HasFailure()) {
      std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "---- scenewatch-ros log ----\n"
                << (bridge_ ? bridge_->stderr_text() : std::string()) << "-------------------------\n";
    }
    bridge_.reset();
    daemon_ = Daemon();
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  /// Starts the bridge against the daemon and waits for its "ready".
  void start_bridge(std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{bridge_binary().string(), "--port", std::to_string(daemon_.port()), "--token-file",
                                  daemon_.token_file().string(), "--world-frame", "world", "--camera-frame", "camera_optical",
                                  "--depth-topic", "/camera/depth/image_rect_raw", "--color-topic", "/camera/color/image_raw",
                                  "--info-topic", "/camera/depth/camera_info"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto child = ChildProcess::start(argv, tmp_ / "scenewatch-ros.log");
    ASSERT_TRUE(child.has_value());
    bridge_ = std::make_unique<ChildProcess>(std::move(*child));
    const auto line = bridge_->read_line(kStartTimeoutS);
    ASSERT_TRUE(line.has_value()) << "scenewatch-ros did not say ready; its log:\n" << bridge_->stderr_text();
    ASSERT_EQ(*line, "ready");
  }

  /// SIGTERM to the bridge: its exit code and its last stats line.
  std::pair<std::optional<int>, std::string> stop_bridge() {
    bridge_->signal(SIGTERM);
    std::string stats;
    while (auto line = bridge_->read_line(kStartTimeoutS)) {
      if (line->rfind("stats:", 0) == 0) stats = *line;
    }
    return {bridge_->wait(kStartTimeoutS), stats};
  }

  fs::path tmp_ = make_temp_dir("ros_bridge");
  Daemon daemon_;
  std::unique_ptr<ChildProcess> bridge_;
};

TEST_F(RosBridgeTest, CupAddedOverDdsGivesOneEventTheObjectsAndTheMap) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 320, 240, 12);
  ASSERT_TRUE(shipped.simulator);
  const sim::Scenario& scenario = shipped.scenario;
  auto& simulator = shipped.simulator;
  const auto truth = simulator->changes();
  ASSERT_EQ(truth.size(), 1u);
  const Eigen::Vector2d where = truth[0].added.at(0).T_world_object.translation().head<2>();
  // The cup's centre: its frame's origin is the centre of its base, z up its axis.
  const sim::PlacedObject& cup = truth[0].added.at(0);
  const Eigen::Vector3d cup_center = cup.T_world_object * Eigen::Vector3d(0, 0, 0.5 * cup.object.shape.total_height_m());

  const fs::path model_dir = tmp_ / "model";
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "  model_dir: " + model_dir.string() + "\nsegmentation:\n  up_vector: [0, 0, 1]\n"));
  ASSERT_NO_FATAL_FAILURE(start_bridge({"--map-period", "0.5"}));

  CameraPeer camera(domain);
  ASSERT_TRUE(camera.connect(30.0)) << "the bridge's DDS participant was not discovered";

  // Lock step, as a test must not depend on speed: the next frame goes out once the bridge
  // published the objects of this one (a best-effort image lost on the way is sent again).
  std::vector<double> round_trip_ms, stamps;
  std::vector<std::pair<std::string, Eigen::Vector3d>> last_objects;
  std::vector<std::pair<double, std::vector<ReceivedMarker>>> marker_arrays;  // per frame, in order
  std::size_t retries = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      const double stamp = kStamp0 + static_cast<double>(stamps.size()) / 30.0;
      stamps.push_back(stamp);
      std::optional<std::vector<std::pair<std::string, Eigen::Vector3d>>> objects;
      for (int attempt = 0; attempt < 3 && !objects; ++attempt) {
        retries += attempt > 0;
        const auto published = Clock::now();
        camera.publish(rendered, scenario.intrinsics, stamp);
        objects = camera.objects_of(stamp, kFrameWaitS / 3);
        if (objects) round_trip_ms.push_back(ms_since(published));
      }
      ASSERT_TRUE(objects) << "no Detection3DArray for the frame of " << stamp - kStamp0 << " s";
      last_objects = *objects;
      // The markers follow the objects (after a GetHands), on the same reliable QoS.
      auto markers = camera.markers_of(stamp, kFrameWaitS);
      ASSERT_TRUE(markers) << "no MarkerArray for the frame of " << stamp - kStamp0 << " s";
      marker_arrays.emplace_back(stamp, std::move(*markers));
    }
  }

  // The change, once: exactly one event, OBJECT_ADDED, where the truth put the cup.
  std::vector<std::tuple<std::uint8_t, std::string, Eigen::Vector2d>> events;
  std::vector<ReceivedEvent> event_boxes;
  const auto waited = Clock::now();
  while (ms_since(waited) < (events.empty() ? kFrameWaitS * 1000 : 1500)) {
    DdsPeer::take<scenewatch_msgs_msg_dds__EventArray_>(camera.events_reader(), [&](const scenewatch_msgs_msg_dds__EventArray_& m) {
      for (std::uint32_t i = 0; i < m.events._length; ++i) {
        const auto& e = m.events._buffer[i];
        events.emplace_back(e.kind, e.kind_name, Eigen::Vector2d(e.centroid.x, e.centroid.y));
        event_boxes.push_back({e.id, ros::seconds(e.header.stamp), Eigen::Vector3d(e.box_min.x, e.box_min.y, e.box_min.z),
                               Eigen::Vector3d(e.box_max.x, e.box_max.y, e.box_max.z)});
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(events.size(), 1u) << "one fact, one event";
  EXPECT_EQ(std::get<0>(events[0]), scenewatch_msgs_msg_dds__Event_Constants_OBJECT_ADDED);
  EXPECT_EQ(std::get<1>(events[0]), "OBJECT_ADDED");
  EXPECT_LT((std::get<2>(events[0]) - where).norm(), 0.10);

  // The objects: the last Detection3DArray is the daemon's object list, object for object.
  service::Client client = daemon_.connect();
  const auto objects = call(client, request([](proto::Request& r) { r.mutable_get_objects(); }));
  ASSERT_GT(objects.objects().objects_size(), 0);
  ASSERT_EQ(last_objects.size(), static_cast<std::size_t>(objects.objects().objects_size()));
  for (int i = 0; i < objects.objects().objects_size(); ++i) {
    const auto& o = objects.objects().objects(i);
    const auto& [id, center] = last_objects[static_cast<std::size_t>(i)];
    EXPECT_EQ(id, std::to_string(o.id()));
    EXPECT_LT((center - Eigen::Vector3d(o.box().center().x(), o.box().center().y(), o.box().center().z())).norm(), 1e-9);
  }

  expect_markers(marker_arrays, objects.objects().objects(), event_boxes.at(0), cup_center, scenario.table.height_m);

  // The surprise heatmaps: one per frame the memory could predict (every frame after the first,
  // which became its first keyframe), 32FC1 in the camera's frame; the last one is, byte for
  // byte, the daemon's GetSurpriseMap.
  const auto heatmaps = camera.heatmaps_until(stamps.back(), kFrameWaitS);
  const auto surprise = call(client, request([](proto::Request& r) { r.mutable_get_surprise_map(); }));
  ASSERT_EQ(surprise.status().code(), proto::Status::OK) << surprise.status().message();
  ASSERT_FALSE(heatmaps.empty()) << "no surprise heatmap";
  EXPECT_GE(heatmaps.size(), stamps.size() - 1) << "best effort on loopback: none should be lost";
  for (const auto& h : heatmaps) {
    EXPECT_EQ(h.encoding, "32FC1");
    EXPECT_EQ(h.frame_id, "camera_optical");
    EXPECT_EQ(h.is_bigendian, 0);
    EXPECT_EQ(h.width, surprise.surprise_map().width());
    EXPECT_EQ(h.height, surprise.surprise_map().height());
    EXPECT_EQ(h.step, 4 * h.width);
    EXPECT_EQ(h.data.size(), static_cast<std::size_t>(h.step) * h.height);
    EXPECT_NE(std::find_if(stamps.begin(), stamps.end(), [&](double t) { return std::abs(t - h.stamp_s) < 1e-6; }), stamps.end());
  }
  ASSERT_LT(std::abs(heatmaps.back().stamp_s - stamps.back()), 1e-6) << "no heatmap of the last frame";
  EXPECT_LT(std::abs(surprise.surprise_map().stamp_s() - stamps.back()), 1e-6);
  EXPECT_TRUE(heatmaps.back().data == surprise.surprise_map().total()) << "the last heatmap is not the daemon's";
  std::size_t finite = 0;
  for (std::size_t i = 0; i + 4 <= heatmaps.back().data.size(); i += 4) {
    float v;
    std::memcpy(&v, heatmaps.back().data.data() + i, 4);
    finite += std::isfinite(v);
  }
  EXPECT_GT(finite, 0u) << "the memory predicts no pixel of the last frame";
  std::printf("surprise heatmaps: %zu of %zu frames, %ux%u, %zu pixels predicted in the last\n", heatmaps.size(), stamps.size(),
              heatmaps.back().width, heatmaps.back().height, finite);

  // The map: the Octomap of the last frame, read by OctoMap's readBinaryData, is the tree the daemon
  // saves (same resolution, same nodes, same occupancy leaf for leaf).
  std::unique_ptr<octomap::OcTree> received;
  std::string map_id;
  const auto map_wait = Clock::now();
  while (!received && ms_since(map_wait) < kFrameWaitS * 1000) {
    DdsPeer::take<octomap_msgs_msg_dds__Octomap_>(camera.map_reader(), [&](const octomap_msgs_msg_dds__Octomap_& m) {
      if (std::abs(ros::seconds(m.header.stamp) - stamps.back()) > 1e-6) return;
      EXPECT_TRUE(m.binary);
      map_id = m.id;
      received = std::make_unique<octomap::OcTree>(m.resolution);
      std::istringstream data(std::string(reinterpret_cast<const char*>(m.data._buffer), m.data._length));
      EXPECT_TRUE(received->readBinaryData(data).good());
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(received) << "no Octomap of the last frame";
  EXPECT_EQ(map_id, "OcTree");
  ASSERT_EQ(call(client, request([](proto::Request& r) { r.mutable_save_model(); })).status().code(), proto::Status::OK);
  std::ifstream saved_file(model_dir / "current" / "background.ot", std::ios::binary);
  ASSERT_TRUE(saved_file) << "no saved map in " << model_dir;
  std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(saved_file));
  auto* saved = dynamic_cast<octomap::ColorOcTree*>(read.get());
  ASSERT_NE(saved, nullptr);
  EXPECT_EQ(received->getResolution(), saved->getResolution());
  EXPECT_EQ(received->size(), saved->size());
  EXPECT_EQ(received->getNumLeafNodes(), saved->getNumLeafNodes());
  std::size_t occupied = 0, mismatched = 0;
  for (auto it = saved->begin_leafs(), end = saved->end_leafs(); it != end; ++it) {
    const octomap::OcTreeNode* node = received->search(it.getKey(), it.getDepth());
    const bool occupied_here = saved->isNodeOccupied(*it);
    occupied += occupied_here;
    if (node == nullptr || received->isNodeOccupied(node) != occupied_here) ++mismatched;
  }
  EXPECT_GT(occupied, 100u);
  EXPECT_EQ(mismatched, 0u);

  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0)) << bridge_->stderr_text();
  const auto sent_at = stats.find("frames_sent=");
  ASSERT_NE(sent_at, std::string::npos) << stats;
  EXPECT_GE(std::stoul(stats.substr(sent_at + 12)), stamps.size()) << stats;
  EXPECT_EQ(stats.find("dropped."), std::string::npos) << "lock step: nothing to drop; " << stats;
  std::printf("scenewatch-ros on %zu frames of 320x240 (%zu sent again): %s\n", stamps.size(), retries, stats.c_str());
  std::printf("publish -> Detection3DArray back, through DDS, the bridge and the daemon: median %.1f ms\n", median(round_trip_ms));
}

// A hand picks up the cup: the markers of every frame draw the hands (and the person's box) that
// the daemon's GetHands reports for that frame, box for box.
TEST_F(RosBridgeTest, HandMarkersAreTheDaemonsHandsOfEachFrame) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("hand_picks_cup_upright", 320, 240);
  ASSERT_TRUE(shipped.simulator);
  auto& simulator = shipped.simulator;
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "segmentation:\n  up_vector: [0, 0, 1]\n"));
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  CameraPeer camera(domain);
  ASSERT_TRUE(camera.connect(30.0)) << "the bridge's DDS participant was not discovered";
  service::Client client = daemon_.connect();

  std::size_t frames = 0, frames_with_hands = 0, hand_boxes = 0, person_boxes = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      const double stamp = kStamp0 + static_cast<double>(frames++) / 30.0;
      std::optional<std::vector<ReceivedMarker>> markers;
      for (int attempt = 0; attempt < 3 && !markers; ++attempt) {
        camera.publish(rendered, shipped.scenario.intrinsics, stamp);
        markers = camera.markers_of(stamp, kFrameWaitS / 3);
      }
      ASSERT_TRUE(markers) << "no MarkerArray for frame " << frames;
      // Lock step: the daemon's last frame is this one until the test publishes the next.
      const auto hands = call(client, request([](proto::Request& r) { r.mutable_get_hands(); })).hands();
      ASSERT_NEAR(hands.stamp_s(), stamp, 1e-6);
      const auto drawn = markers_in(*markers, "hands", visualization_msgs_msg_dds__Marker_Constants_CUBE);
      ASSERT_EQ(drawn.size(), static_cast<std::size_t>(hands.hands_size())) << "frame " << frames;
      for (int i = 0; i < hands.hands_size(); ++i) {
        const auto& box = hands.hands(i).box_world();
        const Eigen::Vector3d lo(box.min().x(), box.min().y(), box.min().z()), hi(box.max().x(), box.max().y(), box.max().z());
        EXPECT_LT((drawn[static_cast<std::size_t>(i)]->position - 0.5 * (lo + hi)).norm(), 1e-9);
        EXPECT_LT((drawn[static_cast<std::size_t>(i)]->scale - (hi - lo)).norm(), 1e-9);
      }
      const auto person = markers_in(*markers, "person", visualization_msgs_msg_dds__Marker_Constants_CUBE);
      EXPECT_EQ(person.size(), hands.has_person_box_world() ? 1u : 0u);
      frames_with_hands += hands.hands_size() > 0;
      hand_boxes += drawn.size();
      person_boxes += person.size();
    }
  }
  EXPECT_GT(frames_with_hands, 0u) << "the daemon saw no hand in " << frames << " frames of a hand picking up a cup";
  std::printf("hands drawn in %zu of %zu frames (%zu boxes), the person's box in %zu\n", frames_with_hands, frames, hand_boxes,
              person_boxes);
}

// --publish-odom-tf: the camera's poses come from the robot's odometry (odom -> rig -> camera),
// the daemon refines them against its memory, and the bridge publishes its correction, world ->
// odom, on /tf after each frame: the T_world_odom that GetLocalization reports, which undoes a
// 2 cm slip of the odometry the test makes.
TEST_F(RosBridgeTest, TheDaemonsOdometryCorrectionIsPublishedOnTf) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 320, 240, 16);
  ASSERT_TRUE(shipped.simulator);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "segmentation:\n  up_vector: [0, 0, 1]\nlocalization:\n  mode: refine\n"));
  ASSERT_NO_FATAL_FAILURE(start_bridge({"--publish-odom-tf", "--odom-frame", "odom"}));
  CameraPeer camera(domain, "odom");
  DdsPeer listener(domain);  // a tf2 listener of its own, as RViz's would be
  const dds_entity_t tf_r = listener.entity("/tf", &tf2_msgs_msg_dds__TFMessage__desc, true, true, 100);
  ASSERT_TRUE(camera.connect(30.0));
  ASSERT_TRUE(DdsPeer::wait_matched({}, {tf_r}, 30.0)) << "no /tf writer of the bridge";

  // The odometry slips by 2 cm along x from the fifth frame on: the daemon's refine should find
  // world -> odom near the inverse, a shift of -2 cm.
  constexpr int kDriftFrom = 4;
  Pose T_drift = Pose::Identity();
  T_drift.translation() = Eigen::Vector3d(0.02, 0, 0);
  double stamp = kStamp0;
  for (int f = 0; f < shipped.simulator->frame_count(0); ++f) {
    const sim::SimFrame rendered = shipped.simulator->render(0, f);
    stamp = kStamp0 + f / 30.0;
    camera.publish(rendered, shipped.scenario.intrinsics, stamp, true, f >= kDriftFrom ? T_drift : Pose::Identity());
    ASSERT_TRUE(camera.objects_of(stamp, kFrameWaitS)) << "no objects for frame " << f;
  }
  // The last frame's world -> odom, as the listener received it (the camera's own /tf links are
  // odom -> ... and are skipped).
  std::optional<Pose> received;
  const auto waited = Clock::now();
  while (!received && ms_since(waited) < kFrameWaitS * 1000) {
    DdsPeer::take<tf2_msgs_msg_dds__TFMessage_>(tf_r, [&](const tf2_msgs_msg_dds__TFMessage_& m) {
      for (std::uint32_t i = 0; i < m.transforms._length; ++i) {
        const auto& t = m.transforms._buffer[i];
        if (std::string(t.header.frame_id) != "world" || std::string(t.child_frame_id) != "odom") continue;
        if (std::abs(ros::seconds(t.header.stamp) - stamp) > 1e-6) continue;
        const auto& q = t.transform.rotation;
        EXPECT_NEAR(std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w), 1.0, 1e-9);
        received = Pose::Identity();
        received->linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
        received->translation() = Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(received) << "no world -> odom on /tf for the last frame";

  service::Client client = daemon_.connect();
  const auto where = call(client, request([](proto::Request& r) { r.mutable_get_localization(); }));
  ASSERT_EQ(where.localization().cameras_size(), 1);
  const auto& result = where.localization().cameras(0);
  EXPECT_EQ(result.mode(), "refine");
  ASSERT_EQ(result.t_world_odom().matrix_size(), 16);
  Eigen::Matrix4d expected;
  for (int i = 0; i < 16; ++i) expected(i / 4, i % 4) = result.t_world_odom().matrix(i);
  EXPECT_LT((received->matrix() - expected).cwiseAbs().maxCoeff(), 1e-9) << "the daemon's T_world_odom:\n" << expected;
  // Measured -15.7 mm after 12 frames of the slip: refine's filter (drift prior 1 mm per frame)
  // takes the 2 cm in over several frames.
  EXPECT_LT(received->translation().x(), -0.012) << "the correction does not undo the odometry's slip";
  EXPECT_LT(received->translation().tail<2>().norm(), 0.002);
  std::printf("world -> odom after %d frames (refine, state %s): (%.2f, %.2f, %.2f) mm, %.3f deg\n", shipped.simulator->frame_count(0),
              result.state().c_str(), received->translation().x() * 1000, received->translation().y() * 1000, received->translation().z() * 1000,
              Eigen::AngleAxisd(received->linear()).angle() * 180 / M_PI);
  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0));
  EXPECT_NE(stats.find("odom_sent="), std::string::npos) << stats;
}

// An organized sensor_msgs/PointCloud2 (--cloud-topic), as depth_image_proc or a driver's
// pointcloud option publishes it, with no CameraInfo: each cloud is a frame, its pinhole estimated
// from the points, and the change is found once. Meanwhile a bystander subscribes to the outputs
// and never takes a sample (a stalled subscriber: reliable, keep last 1, as a ROS 2 node whose
// executor hangs), then vanishes halfway without a word: the bridge neither stalls nor fails a
// write. (A KEEP_ALL reader whose resource limits are full was tried too: in Cyclone it stalls the
// delivery of that writer to every reader of its own process, the test's included, so it cannot
// be tested from inside this process.)
TEST_F(RosBridgeTest, AnOrganizedPointCloud2IsAFrameAndSlowOrVanishingSubscribersDoNotStallTheBridge) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 320, 240, 12);
  ASSERT_TRUE(shipped.simulator);
  auto& simulator = shipped.simulator;
  const auto truth = simulator->changes();
  ASSERT_EQ(truth.size(), 1u);
  const Eigen::Vector2d where = truth[0].added.at(0).T_world_object.translation().head<2>();
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "segmentation:\n  up_vector: [0, 0, 1]\n"));
  ASSERT_NO_FATAL_FAILURE(start_bridge({"--cloud-topic", "/camera/depth/points", "--no-markers", "--no-surprise", "--map-period", "0.2"}));
  CameraPeer camera(domain);
  ASSERT_TRUE(camera.connect(30.0, /*markers=*/false, /*cloud=*/true)) << "the bridge's DDS participant was not discovered";

  auto bystander = std::make_unique<DdsPeer>(domain);
  std::vector<dds_entity_t> idle_readers;
  for (const auto& [topic, type] : {std::pair<const char*, const dds_topic_descriptor_t*>{"rt/scenewatch/objects", &vision_msgs_msg_dds__Detection3DArray__desc},
                                    {"rt/scenewatch/events", &scenewatch_msgs_msg_dds__EventArray__desc},
                                    {"rt/scenewatch/octomap_binary", &octomap_msgs_msg_dds__Octomap__desc}}) {
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    if (std::string(topic).find("octomap") != std::string::npos) dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    idle_readers.push_back(bystander->reader_with(topic, type, q));
    dds_delete_qos(q);
  }
  ASSERT_TRUE(DdsPeer::wait_matched({}, idle_readers, 30.0)) << "the bystander did not match the bridge's writers";

  std::size_t frames = 0, answered = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      const double stamp = kStamp0 + static_cast<double>(frames++) / 30.0;
      bool got = false;
      for (int attempt = 0; attempt < 3 && !got; ++attempt) {
        ASSERT_NO_FATAL_FAILURE(camera.publish_cloud(rendered, shipped.scenario.intrinsics, stamp));
        got = camera.objects_of(stamp, kFrameWaitS / 3).has_value();
      }
      answered += got;
      if (frames == 12) bystander.reset();  // vanishes without a word
    }
  }
  EXPECT_EQ(answered, frames) << "every cloud gives its Detection3DArray";

  std::vector<std::pair<std::string, Eigen::Vector2d>> events;
  const auto waited = Clock::now();
  while (ms_since(waited) < (events.empty() ? kFrameWaitS * 1000 : 1500)) {
    DdsPeer::take<scenewatch_msgs_msg_dds__EventArray_>(camera.events_reader(), [&](const scenewatch_msgs_msg_dds__EventArray_& m) {
      for (std::uint32_t i = 0; i < m.events._length; ++i) {
        events.emplace_back(m.events._buffer[i].kind_name, Eigen::Vector2d(m.events._buffer[i].centroid.x, m.events._buffer[i].centroid.y));
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(events.size(), 1u) << "one fact, one event";
  EXPECT_EQ(events[0].first, "OBJECT_ADDED");
  EXPECT_LT((events[0].second - where).norm(), 0.10);

  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0)) << bridge_->stderr_text();
  EXPECT_NE(stats.find("cloud_in="), std::string::npos) << stats;
  EXPECT_EQ(stats.find("depth_in"), std::string::npos) << "no image reader with --cloud-topic; " << stats;
  EXPECT_EQ(stats.find("dropped."), std::string::npos) << "lock step: nothing to drop; " << stats;
  EXPECT_EQ(stats.find("write_failed"), std::string::npos) << "a write blocked on the idle subscriber; " << stats;
  std::printf("PointCloud2 frames: %zu of %zu answered, event %s %.1f cm from the cup; %s\n", answered, frames, events[0].first.c_str(),
              100 * (events[0].second - where).norm(), stats.c_str());
}

// A subscriber in another process whose KEEP_ALL readers, on every reliable topic the bridge
// writes, hold two samples and never read (tests/ros/stalled_subscriber.cpp): once full, it
// acknowledges nothing more. The bridge must go on answering every frame with no write given up,
// and the test's own subscriber must still get the event. The latencies are printed (a writer that
// waited on the stalled reader would show its blocking time, up to 1 s), not asserted.
TEST_F(RosBridgeTest, AStalledKeepAllSubscriberInAnotherProcessDoesNotStallTheBridge) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 320, 240, 12);
  ASSERT_TRUE(shipped.simulator);
  auto& simulator = shipped.simulator;
  std::vector<sim::SimFrame> rendered;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) rendered.push_back(simulator->render(phase, f));
  }
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "segmentation:\n  up_vector: [0, 0, 1]\n"));
  // The map after every frame: the largest message, so that unacknowledged data grows fastest.
  ASSERT_NO_FATAL_FAILURE(start_bridge({"--map-period", "0"}));
  CameraPeer camera(domain);
  ASSERT_TRUE(camera.connect(30.0)) << "the bridge's DDS participant was not discovered";
  auto child = ChildProcess::start({stalled_subscriber_binary().string(), std::to_string(domain), "2"}, tmp_ / "stalled.log");
  ASSERT_TRUE(child.has_value());
  ASSERT_EQ(child->read_line(30.0).value_or(""), "matched") << child->stderr_text();

  // Lock step: each frame's answer (its Detection3DArray) timed from its publication.
  std::vector<double> answer_ms;
  std::size_t events = 0;
  auto take_events = [&] {
    DdsPeer::take<scenewatch_msgs_msg_dds__EventArray_>(camera.events_reader(),
                                                         [&](const scenewatch_msgs_msg_dds__EventArray_& m) { events += m.events._length; });
  };
  for (std::size_t i = 0; i < rendered.size(); ++i) {
    const double stamp = kStamp0 + static_cast<double>(i) / 30.0;
    const auto published = Clock::now();
    camera.publish(rendered[i], shipped.scenario.intrinsics, stamp);
    if (camera.objects_of(stamp, kFrameWaitS)) answer_ms.push_back(ms_since(published));
    take_events();
  }
  for (const auto waited = Clock::now(); events == 0 && ms_since(waited) < kFrameWaitS * 1000;) {
    take_events();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(answer_ms.size(), rendered.size()) << "every frame gives its Detection3DArray";
  EXPECT_EQ(events, 1u) << "the test's own subscriber gets the one event";
  ASSERT_EQ(child->wait(0.0), std::nullopt) << "the stalled subscriber is still there, unread: " << child->stderr_text();
  std::size_t rejected = 0;
  // It says so at most every 0.1 s, for as long as the writers retry: read for a second.
  for (const auto read_from = Clock::now(); ms_since(read_from) < 1000;) {
    const auto line = child->read_line(0.2);
    if (line && line->rfind("rejected ", 0) == 0) rejected = std::stoul(line->substr(9));
  }
  EXPECT_GT(rejected, 0u) << "its readers were never full: nothing was tested";
  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0)) << bridge_->stderr_text();
  EXPECT_EQ(stats.find("dropped."), std::string::npos) << "lock step: nothing to drop; " << stats;
  std::sort(answer_ms.begin(), answer_ms.end());
  const double median = answer_ms.empty() ? 0.0 : answer_ms[answer_ms.size() / 2];
  const auto request_to_reply = stats.find("daemon.request_to_reply_ms={");
  std::printf("with a stalled KEEP_ALL subscriber (%zu samples refused): %zu of %zu frames answered, median %.1f ms from "
              "publication to the Detection3DArray, max %.1f ms; %s\n",
              rejected, answer_ms.size(), rendered.size(), median, answer_ms.empty() ? 0.0 : answer_ms.back(),
              request_to_reply == std::string::npos ? stats.c_str() : stats.substr(request_to_reply).c_str());
  EXPECT_EQ(stats.find("write_failed"), std::string::npos) << "a write gave up on the stalled subscriber; " << stats;
  EXPECT_EQ(stats.find("outputs_dropped"), std::string::npos) << "writes fell behind the frames; " << stats;
}

/// A counter of the bridge's stats line ("name=N"), 0 when absent.
std::size_t stat(const std::string& stats, const std::string& name) {
  const auto at = stats.find(" " + name + "=");
  return at == std::string::npos ? 0 : std::stoul(stats.substr(at + name.size() + 2));
}

// VGA, as a RealSense or Kinect driver sends it. First in lock step (the next frame once the
// previous one's objects came back): the latency the bridge adds with the daemon idle. Then, with
// a fresh bridge, a stream at 30 Hz: the bridge keeps up as far as the daemon does and accounts
// for every depth image it took (sent, skipped by the daemon as stale, or dropped with a reason).
// Prints the latencies and the frames per second that reached the model (figures for
// docs/ros2.md, not asserted: timing is no test's business).
TEST_F(RosBridgeTest, AtVgaTheBridgeAddsLittleAndAccountsForEveryFrameOfA30HzStream) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 640, 480, 30);
  ASSERT_TRUE(shipped.simulator);
  std::vector<sim::SimFrame> rendered;
  for (std::size_t phase = 0; phase < shipped.simulator->phase_count(); ++phase) {
    for (int f = 0; f < shipped.simulator->frame_count(phase); ++f) rendered.push_back(shipped.simulator->render(phase, f));
  }
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "segmentation:\n  up_vector: [0, 0, 1]\n"));
  CameraPeer camera(domain);

  // Lock step over the first 20 frames.
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  ASSERT_TRUE(camera.connect(30.0)) << "the bridge's DDS participant was not discovered";
  const std::size_t kLockStep = 20;
  std::size_t answered = 0;
  for (std::size_t i = 0; i < kLockStep; ++i) {
    const double stamp = kStamp0 + static_cast<double>(i) / 30.0;
    bool got = false;
    for (int attempt = 0; attempt < 3 && !got; ++attempt) {
      camera.publish(rendered[i], shipped.scenario.intrinsics, stamp);
      got = camera.objects_of(stamp, kFrameWaitS / 3).has_value();
    }
    answered += got;
  }
  EXPECT_EQ(answered, kLockStep);
  const auto [lock_code, lock_stats] = stop_bridge();
  EXPECT_EQ(lock_code, std::optional<int>(0)) << bridge_->stderr_text();
  EXPECT_EQ(stat(lock_stats, "frames_sent"), kLockStep) << lock_stats;
  std::printf("VGA in lock step, %zu frames: %s\n", kLockStep, lock_stats.c_str());

  // The rest at 30 Hz.
  ASSERT_NO_FATAL_FAILURE(start_bridge());
  ASSERT_TRUE(camera.connect(30.0)) << "the second bridge was not discovered";
  const auto start = Clock::now();
  double last_stamp = 0;
  for (std::size_t i = kLockStep; i < rendered.size(); ++i) {
    std::this_thread::sleep_until(start + std::chrono::microseconds(static_cast<long>((i - kLockStep) * 1e6 / 30)));
    last_stamp = kStamp0 + static_cast<double>(i) / 30.0;
    camera.publish(rendered[i], shipped.scenario.intrinsics, last_stamp);
  }
  const double published_s = ms_since(start) / 1000;
  const bool last_answered = camera.objects_of(last_stamp, 10.0).has_value();  // unless it was dropped
  const double answered_s = ms_since(start) / 1000;
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0)) << bridge_->stderr_text();
  const std::size_t streamed = rendered.size() - kLockStep;
  const std::size_t taken = stat(stats, "depth_in"), sent = stat(stats, "frames_sent"), skipped = stat(stats, "skipped_by_daemon");
  std::size_t dropped = 0;
  for (std::size_t at = stats.find(" dropped."); at != std::string::npos; at = stats.find(" dropped.", at + 1)) {
    dropped += std::stoul(stats.substr(stats.find('=', at) + 1));
  }
  EXPECT_GT(taken, streamed / 2) << "best effort on loopback lost most images; " << stats;
  EXPECT_GT(sent, 0u) << stats;
  EXPECT_EQ(taken, sent + skipped + dropped) << "a frame went missing without a count; " << stats;
  std::printf("VGA at 30 Hz: %zu frames published in %.2f s; the bridge took %zu, sent %zu (%zu skipped by the daemon as stale, "
              "%zu dropped); %.1f frames per second reached the model, from the first frame to the last answer (%.2f s%s)\n%s\n",
              streamed, published_s, taken, sent, skipped, dropped, static_cast<double>(sent - skipped) / answered_s, answered_s,
              last_answered ? "" : ", the last frame dropped: its wait included", stats.c_str());
}

// The daemon vanishes (killed) and comes back on the same port: the bridge keeps running,
// reconnects with backoff and carries on. A frame whose TF never comes is dropped with its reason
// counted, not sent. Run with --no-markers and --no-surprise, which must leave neither topic.
TEST_F(RosBridgeTest, AVanishedDaemonIsReconnectedToAndAFrameWithoutTfIsDropped) {
  const std::uint32_t domain = configure_loopback_dds();
  ShippedScenario shipped = shipped_scenario("cup_added", 320, 240, 4);
  ASSERT_TRUE(shipped.simulator);
  const sim::SimFrame rendered = shipped.simulator->render(0, 0);
  const Intrinsics& K = shipped.scenario.intrinsics;

  // A port of our own (the daemon must come back on it): one the kernel just gave out.
  std::uint16_t port = 0;
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len), 0);
    port = ntohs(a.sin_port);
    ::close(fd);
  }
  const fs::path config = tmp_ / "scenewatchd.yaml";
  std::ofstream(config) << "server:\n  address: 127.0.0.1\n  port: " << port << "\n  token_file: " << (tmp_ / "token").string()
                        << "\nsegmentation:\n  up_vector: [0, 0, 1]\n";
  auto start_daemon = [&](int n) {
    auto child = ChildProcess::start({daemon_binary().string(), "--config", config.string()}, tmp_ / ("scenewatchd-" + std::to_string(n) + ".log"));
    EXPECT_TRUE(child.has_value());
    auto line = child->read_line(kStartTimeoutS);
    EXPECT_TRUE(line && line->rfind("listening on", 0) == 0) << child->stderr_text();
    return std::make_unique<ChildProcess>(std::move(*child));
  };
  auto daemon = start_daemon(1);
  std::vector<std::string> argv{bridge_binary().string(), "--port", std::to_string(port), "--token-file", (tmp_ / "token").string(),
                                "--world-frame", "world", "--camera-frame", "camera_optical", "--depth-topic",
                                "/camera/depth/image_rect_raw", "--color-topic", "/camera/color/image_raw", "--info-topic",
                                "/camera/depth/camera_info", "--max-backoff", "0.5", "--tf-wait", "0.2", "--no-markers",
                                "--no-surprise"};
  auto child = ChildProcess::start(argv, tmp_ / "scenewatch-ros.log");
  ASSERT_TRUE(child.has_value());
  bridge_ = std::make_unique<ChildProcess>(std::move(*child));
  ASSERT_EQ(bridge_->read_line(kStartTimeoutS).value_or(""), "ready") << bridge_->stderr_text();
  CameraPeer camera(domain);
  ASSERT_TRUE(camera.connect(30.0, /*markers=*/false));

  double stamp = kStamp0;
  auto sent_and_answered = [&](double timeout_s) {
    const auto start = Clock::now();
    while (ms_since(start) < timeout_s * 1000) {
      camera.publish(rendered, K, stamp += 1.0);
      if (camera.objects_of(stamp, 1.0)) return true;
    }
    return false;
  };
  ASSERT_TRUE(sent_and_answered(kFrameWaitS));

  // No TF at this stamp (the last /tf sample is 1 s older, --tf-tolerance 0.05 s): dropped. The
  // next frame, with its TF, goes through and drops the one that waited.
  camera.publish(rendered, K, stamp += 1.0, /*with_tf=*/false);
  EXPECT_FALSE(camera.objects_of(stamp, 1.0));
  ASSERT_TRUE(sent_and_answered(kFrameWaitS));

  daemon->kill_now();
  camera.publish(rendered, K, stamp += 1.0);  // into a broken connection: lost, the bridge reconnects
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(bridge_->wait(0.0), std::nullopt) << "the bridge keeps running without its daemon";
  daemon = start_daemon(2);
  EXPECT_TRUE(sent_and_answered(kFrameWaitS)) << "no objects after the daemon came back";

  // --no-markers, --no-surprise: no MarkerArray or heatmap writer at all, no GetHands or
  // GetSurpriseMap per frame.
  for (dds_entity_t reader : {camera.markers_reader(), camera.surprise_reader()}) {
    dds_subscription_matched_status_t matched{};
    dds_get_subscription_matched_status(reader, &matched);
    EXPECT_EQ(matched.total_count, 0u);
  }
  const auto [code, stats] = stop_bridge();
  EXPECT_EQ(code, std::optional<int>(0)) << bridge_->stderr_text();
  EXPECT_EQ(stats.find("markers_sent"), std::string::npos) << stats;
  EXPECT_EQ(stats.find("surprise_"), std::string::npos) << stats;
  EXPECT_NE(stats.find("dropped.no_tf=1"), std::string::npos) << stats;
  EXPECT_NE(stats.find("reconnects.ingest="), std::string::npos) << stats;
  EXPECT_NE(bridge_->stderr_text().find("(no_tf, 1 so far)"), std::string::npos) << bridge_->stderr_text();
  std::printf("%s\n", stats.c_str());
}

}  // namespace
}  // namespace scenewatch::test
