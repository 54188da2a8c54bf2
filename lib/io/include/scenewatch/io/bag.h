#pragma once
/// Recordings from ROS bags as RGB-D frame sources, like sequence folders (sequence.h):
///   ROS 1 .bag (format 2.0; chunks uncompressed, bz2 or lz4), messages in ROS 1 serialization;
///   rosbag2 with SQLite storage (a folder with metadata.yaml and .db3 files, or one .db3 file),
///   messages in CDR (little-endian, XCDR1, as ROS 2's middlewares write it);
///   MCAP (a .mcap file, or a rosbag2 folder whose storage is mcap; chunks uncompressed, lz4 or
///   zstd, their CRC checked), channels of message encoding cdr or ros1.
/// A frame is a depth image (sensor_msgs/Image 16UC1/mono16 in mm, or 32FC1 in m) with the colour
/// image (rgb8, bgr8, rgba8, bgra8, mono8) nearest in time, each colour image used once, and the
/// intrinsics of a sensor_msgs/CameraInfo; or, without depth images, an organized
/// sensor_msgs/PointCloud2. Its pose is T_world_camera from the bag's tf2_msgs/TFMessage topics
/// (/tf and /tf_static), chained and interpolated at the depth image's header stamp. Topics and
/// frames come from BagOptions, or are guessed from the message types and image encodings when
/// that is unambiguous. Without any TF in the bag the frames have no pose.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

namespace bag {
class Container;
}

/// How a bag is read; every empty string is guessed.
struct BagOptions {
  std::string color_topic;   ///< sensor_msgs/Image in colour
  std::string depth_topic;   ///< sensor_msgs/Image of depth
  std::string info_topic;    ///< sensor_msgs/CameraInfo of the depth camera
  std::string cloud_topic;   ///< organized sensor_msgs/PointCloud2 (used when there is no depth topic)
  std::string world_frame;   ///< TF frame of the world (guessed: the root of the camera frame's tree)
  std::string camera_frame;  ///< TF frame of the camera (guessed: the depth image's header.frame_id)
  /// Colour and depth further apart in time than this are not one frame.
  double max_time_difference_s = 0.02;
  /// How far outside the span of a /tf edge's samples its nearest sample still counts.
  double tf_tolerance_s = 0.05;
};

/// One frame of a bag: the messages it is made of, by index into the container's message list.
struct BagFrame {
  std::size_t depth_message = 0;            ///< the depth image, or the point cloud
  std::optional<std::size_t> color_message;
  double stamp_s = 0.0;                     ///< the depth image's header stamp
  std::optional<Pose> T_world_camera;
};

/// An opened bag. Loading frames reads the file: NOT thread safe; one reader at a time.
struct Recording {
  std::filesystem::path path;
  std::string format;  ///< "ROS 1 bag", "rosbag2 SQLite", "MCAP"
  std::string color_topic, depth_topic, info_topic, cloud_topic;  ///< as chosen; empty: not used
  std::string world_frame, camera_frame;                           ///< empty: no TF, no poses
  std::optional<Intrinsics> intrinsics;
  std::vector<BagFrame> frames;
  /// Depth images left out: no colour image near enough in time, or no transform at their time.
  std::size_t skipped_without_color = 0, skipped_without_pose = 0;
  std::shared_ptr<bag::Container> container;
};

/// True when the path looks like a bag: a .bag, .db3 or .mcap file, or a folder with metadata.yaml.
bool is_bag(const std::filesystem::path& path);

/// Opens a bag, chooses its topics, pairs its images and looks up their poses (reads every image's
/// header, no pixels). Errors name the topic, the message and where it is in the file.
Result<Recording> open_bag(const std::filesystem::path& path, const BagOptions& options = {});

/// What opening left out, for the user; empty when nothing was.
std::string skipped_summary(const Recording& recording, const BagOptions& options = {});

/// Loads one frame of an opened bag (pixels or points decoded, cloud in the camera frame).
Result<Frame> load_bag_frame(Recording& recording, std::size_t index);

}  // namespace scenewatch::io
