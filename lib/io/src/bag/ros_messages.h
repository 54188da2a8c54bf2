#pragma once
// The sensor_msgs and tf2_msgs messages a recording's frames are made of, decoded from either wire
// format. Image and PointCloud2 keep a pointer to their payload in the caller's buffer (no copy);
// the buffer must outlive them. Field layouts: ROS 1 Noetic and ROS 2 Humble/Jazzy .msg files
// (the fields read here are the same in both, except std_msgs/Header's seq, ROS 1 only).
#include <cstdint>
#include <string>
#include <vector>

#include "field_reader.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::io::bag {

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

/// Decoders; errors name the field and the byte within the message.
Result<ImageMessage> decode_image(const std::vector<std::uint8_t>& bytes, WireFormat format);
Result<CameraInfoMessage> decode_camera_info(const std::vector<std::uint8_t>& bytes, WireFormat format);
Result<PointCloud2Message> decode_point_cloud2(const std::vector<std::uint8_t>& bytes, WireFormat format);
/// A TFMessage's transforms; a rotation that is not a unit quaternion (within 1e-3) is an error.
Result<std::vector<StampedTransform>> decode_tf(const std::vector<std::uint8_t>& bytes, WireFormat format);

}  // namespace scenewatch::io::bag
