#pragma once
/// Makes frames out of the ROS 2 streams: a depth image, the colour image with the same stamp
/// (within BridgeConfig::sync_tolerance_s), the last CameraInfo and T_world_camera from /tf and
/// /tf_static at the depth image's stamp (within tf_tolerance_s); or an organized PointCloud2 with
/// its pose (and the last CameraInfo, when one came). A frame whose TF has not arrived
/// yet waits up to tf_wait_s for it; a frame that cannot be made is dropped and the reason counted
/// and logged. Knows no DDS and no sockets. NOT thread safe (the DDS reader thread owns it).
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bridge_config.h"
#include "bridge_stats.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/io/bag/tf_tree.h"

namespace scenewatch::ros {

using Clock = std::chrono::steady_clock;

/// A sensor_msgs/Image copied out of its DDS sample.
struct RawImage {
  double stamp_s = 0.0;
  std::string frame_id;
  std::uint32_t width = 0, height = 0, step = 0;
  std::string encoding;
  bool big_endian = false;
  std::vector<std::uint8_t> data;
  Clock::time_point arrived;  ///< when the bridge took it from DDS
};

/// A sensor_msgs/PointCloud2 copied out of its DDS sample.
struct RawCloud {
  double stamp_s = 0.0;
  std::string frame_id;
  std::uint32_t width = 0, height = 0, point_step = 0, row_step = 0;
  std::vector<io::bag::PointField> fields;
  bool big_endian = false;
  std::vector<std::uint8_t> data;
  Clock::time_point arrived;  ///< when the bridge took it from DDS
};

/// The views io::bag's conversions read (they point into their argument, which must outlive them).
io::bag::ImageMessage image_view(const RawImage& image);
io::bag::PointCloud2Message cloud_view(const RawCloud& cloud);

/// A frame ready for the daemon: images (or a cloud), pinhole, pose (none: the daemon localizes it).
struct FrameJob {
  RawImage depth;                   ///< empty when `cloud` is set
  std::optional<RawImage> color;
  std::optional<RawCloud> cloud;    ///< a PointCloud2 frame (BridgeConfig::cloud_topic)
  std::optional<Intrinsics> intrinsics;  ///< always set for images; for a cloud, when a CameraInfo came
  std::optional<Pose> T_world_camera;
  Clock::time_point arrived;  ///< when its last sample arrived

  double stamp_s() const { return cloud ? cloud->stamp_s : depth.stamp_s; }
  const std::string& frame_id() const { return cloud ? cloud->frame_id : depth.frame_id; }
};

class FrameAssembler {
 public:
  /// `emit` receives each frame made; `log` each line worth logging.
  FrameAssembler(const BridgeConfig& config, BridgeStats& stats, std::function<void(FrameJob)> emit,
                 std::function<void(const std::string&)> log);

  void add_depth(RawImage image);
  void add_color(RawImage image);
  /// A PointCloud2 is a frame of its own (no pairing).
  void add_cloud(RawCloud cloud);
  /// A CameraInfo's pinhole (io::bag::to_intrinsics of it), or its error, counted and logged.
  void set_intrinsics(Result<Intrinsics> intrinsics);
  void add_transform(const io::bag::StampedTransform& t, bool is_static);

 private:
  void try_pair();
  void place(FrameJob job);
  /// A depth image whose colour partner never came.
  void drop_without_color(double stamp_s);
  /// T_world_camera of a frame from the TF tree (the camera frame: --camera-frame, else the
  /// depth image's frame_id).
  Result<Pose> lookup_pose(const FrameJob& job) const;
  void retry_waiting();
  void drop(const std::string& reason, double stamp_s, const std::string& why);

  const BridgeConfig& config_;
  BridgeStats& stats_;
  std::function<void(FrameJob)> emit_;
  std::function<void(const std::string&)> log_;
  std::deque<RawImage> depths_, colors_;
  std::optional<Intrinsics> intrinsics_;
  io::bag::TfTree tf_;
  std::optional<FrameJob> waiting_;  ///< a frame whose TF has not arrived yet
  std::string waiting_error_;
};

}  // namespace scenewatch::ros
