#pragma once
// sensor_msgs pixels into our images and clouds: colour rgb8, bgr8, rgba8, bgra8, mono8; depth
// 16UC1/mono16 in millimetres, 32FC1 in metres (rounded to millimetres, NaN and <= 0 = no depth);
// organized PointCloud2 with FLOAT32 x, y, z and optional rgb/rgba. Row strides and big-endian
// data are honoured; sizes that do not add up are errors.
#include <optional>

#include "scenewatch/io/bag/messages.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"

namespace scenewatch::io::bag {

/// True for the encodings to_color reads; false for those to_depth reads.
bool is_color_encoding(const std::string& encoding);
bool is_depth_encoding(const std::string& encoding);

Result<ColorImage> to_color(const ImageMessage& m);
Result<DepthImage> to_depth(const ImageMessage& m);
/// An organized cloud in the message's frame; error for an unorganized one (height 1).
Result<CloudPtr> to_cloud(const PointCloud2Message& m);

/// A PointCloud2 as a frame's points: to_cloud's cloud, whether the message has an rgb/rgba
/// field, and the pinhole: `info` (a CameraInfo's) when given, else estimated from the points
/// (io::estimate_intrinsics; none when that fails).
struct CloudFrame {
  CloudPtr cloud;
  bool has_color = false;
  std::optional<Intrinsics> intrinsics;
};
Result<CloudFrame> to_cloud_frame(const PointCloud2Message& m, const std::optional<Intrinsics>& info);

/// The pinhole of a CameraInfo's K and size; error unless the focal lengths are positive and finite.
Result<Intrinsics> to_intrinsics(const CameraInfoMessage& m);

/// An RGB-D frame's images, checked against each other and the camera info.
struct RgbdImages {
  DepthImage depth;       ///< millimetres
  ColorImage color;       ///< grey (128) without a colour image
  Intrinsics intrinsics;  ///< K with the depth image's size
  bool has_color = true;
};
/// A depth image (16UC1 mm or 32FC1 m) with an optional colour image registered to it (same size)
/// and K, whose size, when set, must be the depth image's (`info_name` names it in that error). On
/// error, *color_at_fault tells whether the colour image or the depth image was.
Result<RgbdImages> to_rgbd_images(const ImageMessage& depth, const ImageMessage* color, Intrinsics K,
                                  const std::string& info_name, bool* color_at_fault);

/// An RGB-D frame's organized cloud in the camera frame.
struct RgbdCloud {
  CloudPtr cloud;
  Intrinsics intrinsics;  ///< K with the depth image's size
  bool has_color = true;  ///< false without a colour image (the points are grey)
};
/// Back-projects to_rgbd_images' images through K.
Result<RgbdCloud> to_rgbd_cloud(const ImageMessage& depth, const ImageMessage* color, Intrinsics K,
                                const std::string& info_name, bool* color_at_fault);

}  // namespace scenewatch::io::bag
