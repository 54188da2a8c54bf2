#pragma once
// sensor_msgs pixels into our images and clouds: colour rgb8, bgr8, rgba8, bgra8, mono8; depth
// 16UC1/mono16 in millimetres, 32FC1 in metres (rounded to millimetres, NaN and <= 0 = no depth);
// organized PointCloud2 with FLOAT32 x, y, z and optional rgb/rgba. Row strides and big-endian
// data are honoured; sizes that do not add up are errors.
#include "ros_messages.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/image.h"

namespace scenewatch::io::bag {

/// True for the encodings to_color reads; false for those to_depth reads.
bool is_color_encoding(const std::string& encoding);
bool is_depth_encoding(const std::string& encoding);

Result<ColorImage> to_color(const ImageMessage& m);
Result<DepthImage> to_depth(const ImageMessage& m);
/// An organized cloud in the message's frame; error for an unorganized one (height 1).
Result<CloudPtr> to_cloud(const PointCloud2Message& m);

}  // namespace scenewatch::io::bag
