#pragma once
/// What scenewatch-ros is told on its command line: the DDS side (domain, topics), the daemon side
/// (host, port, token) and the policies between them (TF matching, queue, map period).
#include <cstddef>
#include <cstdint>
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/service/server_config.h"

namespace scenewatch::ros {

/// What to do with a frame that has no TF within the tolerance.
enum class WithoutTf { kDrop, kTrack };

struct BridgeConfig {
  // DDS / ROS 2 side.
  std::uint32_t domain_id = 0;  ///< ROS_DOMAIN_ID when set, else 0
  std::string depth_topic = "/camera/aligned_depth_to_color/image_raw";
  std::string color_topic = "/camera/color/image_raw";  ///< empty: depth only (grey points)
  std::string info_topic = "/camera/aligned_depth_to_color/camera_info";
  /// Non-empty: frames are the organized sensor_msgs/PointCloud2 of this topic (FLOAT32 x, y, z in
  /// the camera's optical frame, optional rgb/rgba) instead of depth and colour images. The
  /// CameraInfo on info_topic gives the pinhole when one came; else it is estimated from the cloud.
  std::string cloud_topic;
  std::string world_frame = "map";
  /// With publish_odom_tf: the frame the camera poses are looked up in (the robot's odometry) and
  /// the child of the world -> odom transform the bridge publishes on /tf.
  std::string odom_frame = "odom";
  bool publish_odom_tf = false;    ///< publish world -> odom from the daemon's localization (T_world_odom)
  std::string camera_frame;        ///< empty: the depth images' header.frame_id
  double tf_tolerance_s = 0.05;    ///< a /tf sample this far from the image stamp still counts
  double sync_tolerance_s = 0.02;  ///< colour and depth stamps this close make one frame
  double tf_wait_s = 0.5;          ///< how long a frame waits for its TF to arrive
  WithoutTf without_tf = WithoutTf::kDrop;
  std::string output_namespace = "/scenewatch";  ///< events, objects, octomap_binary, markers under it
  std::string camera_name;         ///< IngestFrame.camera (empty: the daemon's default camera)

  // Daemon side.
  std::string host = "127.0.0.1";
  std::uint16_t port = service::kDefaultPort;
  std::string token_file;          ///< empty: ~/.scenewatch/token
  double call_timeout_s = 10.0;    ///< a reply slower than this: the connection is dropped and made again
  double max_backoff_s = 5.0;      ///< reconnection waits 0.1 s, doubling up to this

  // Between the two.
  std::size_t queue_frames = 2;    ///< frames waiting for the daemon; the oldest is dropped beyond
  double map_period_s = 1.0;       ///< the octomap is published at most this often (and once idle)
  bool markers = true;             ///< publish the MarkerArray after each frame (one GetHands more per frame)
  bool surprise = true;            ///< publish the surprise heatmap after each frame (one GetSurpriseMap more per frame)
  std::size_t marker_events = 10;  ///< the newest events drawn as markers
  double stats_period_s = 0.0;     ///< a stats line on stdout this often (0: only at exit)
};

/// The TF frame camera poses are looked up in: the odometry frame when the bridge publishes world ->
/// odom itself (else it would read back its own transform), else the world frame.
inline const std::string& pose_frame(const BridgeConfig& config) {
  return config.publish_odom_tf ? config.odom_frame : config.world_frame;
}

/// The ROS 2 DDS topic name of a ROS topic: "/tf" -> "rt/tf". Errors for an empty or relative name.
Result<std::string> dds_topic_name(const std::string& ros_topic);

}  // namespace scenewatch::ros
