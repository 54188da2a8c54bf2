#pragma once
/// The sensor_msgs and tf2_msgs messages a recording's frames are made of, as plain structs: what
/// the bag readers decode (src/bag/ros_messages.h) and what scenewatch-ros fills from DDS samples.
/// Image and PointCloud2 keep a pointer to their payload in the caller's buffer (no copy); the
/// buffer must outlive them. Field layouts: ROS 1 Noetic and ROS 2 Humble/Jazzy .msg files.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"

namespace scenewatch::io::bag {

/// std_msgs/Header as both formats carry it (ROS 1's seq is read and dropped).
struct MessageHeader {
  double stamp_s = 0.0;
  std::string frame_id;
};

/// sensor_msgs/Image.
struct ImageMessage {
  MessageHeader header;
  std::uint32_t height = 0, width = 0;
  std::string encoding;
  bool big_endian = false;
  std::uint32_t step = 0;  ///< bytes per row
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

/// sensor_msgs/CameraInfo, as far as K.
struct CameraInfoMessage {
  MessageHeader header;
  std::uint32_t height = 0, width = 0;
  double K[9] = {};
};

/// sensor_msgs/PointField.
struct PointField {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;  ///< 7 = FLOAT32
  std::uint32_t count = 0;
};

/// sensor_msgs/PointCloud2.
struct PointCloud2Message {
  MessageHeader header;
  std::uint32_t height = 0, width = 0;
  std::vector<PointField> fields;
  bool big_endian = false;
  std::uint32_t point_step = 0, row_step = 0;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

/// One geometry_msgs/TransformStamped of a tf2_msgs/TFMessage: T_parent_child.
struct StampedTransform {
  double stamp_s = 0.0;
  std::string parent, child;
  Pose T_parent_child = Pose::Identity();
};

}  // namespace scenewatch::io::bag
