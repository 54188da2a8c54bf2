#pragma once
// Decoders of the sensor_msgs and tf2_msgs messages (scenewatch/io/bag/messages.h) from either wire
// format. The fields read are the same in ROS 1 Noetic and ROS 2 Humble/Jazzy, except
// std_msgs/Header's seq, ROS 1 only.
#include <cstdint>
#include <string>
#include <vector>

#include "field_reader.h"
#include "scenewatch/io/bag/messages.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::io::bag {

/// Decoders; errors name the field and the byte within the message.
Result<ImageMessage> decode_image(const std::vector<std::uint8_t>& bytes, WireFormat format);
Result<CameraInfoMessage> decode_camera_info(const std::vector<std::uint8_t>& bytes, WireFormat format);
Result<PointCloud2Message> decode_point_cloud2(const std::vector<std::uint8_t>& bytes, WireFormat format);
/// A TFMessage's transforms; a rotation that is not a unit quaternion (within 1e-3) is an error.
Result<std::vector<StampedTransform>> decode_tf(const std::vector<std::uint8_t>& bytes, WireFormat format);

}  // namespace scenewatch::io::bag
