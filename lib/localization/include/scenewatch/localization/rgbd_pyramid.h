#pragma once
/// An RGB-D image prepared for dense alignment: depth (metres), intensity (0..1), and on the
/// reference side normals and intensity gradients, at a few resolutions, coarse to fine.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::localization {

/// One resolution. Pixels without a usable depth hold 0; normals there are NaN.
struct RgbdLevel {
  int width = 0, height = 0;
  Intrinsics intrinsics;             ///< scaled to this level
  std::vector<float> depth_m;
  std::vector<float> intensity;      ///< 0..1, (R + G + B) / 765
  std::vector<Eigen::Vector3f> normals;  ///< camera frame, towards the camera; reference only
  /// A pixel's intensity with its gradient (per pixel, central differences), side by side: the
  /// alignment samples all three at one sub-pixel position. Reference only.
  struct Shade {
    float intensity = 0.0f, grad_x = 0.0f, grad_y = 0.0f;
  };
  std::vector<Shade> shade;
  std::size_t pixels() const { return static_cast<std::size_t>(width) * height; }
  /// The camera-frame point of a pixel with depth z.
  Eigen::Vector3f point(int u, int v, float z) const { return {ray_x(u) * z, ray_y(v) * z, z}; }
  /// The factors point() scales z by: x / z of column u, y / z of row v.
  float ray_x(int u) const { return static_cast<float>((u - intrinsics.cx) / intrinsics.fx); }
  float ray_y(int v) const { return static_cast<float>((v - intrinsics.cy) / intrinsics.fy); }
};

/// RgbdLevel::point's factors (ray_x, ray_y) per column and per row of a level, computed once
/// instead of two divisions per point: the same values, so the same points.
struct PixelRays {
  std::vector<float> x, y;
  explicit PixelRays(const RgbdLevel& level) : x(static_cast<std::size_t>(level.width)), y(static_cast<std::size_t>(level.height)) {
    for (int u = 0; u < level.width; ++u) x[static_cast<std::size_t>(u)] = level.ray_x(u);
    for (int v = 0; v < level.height; ++v) y[static_cast<std::size_t>(v)] = level.ray_y(v);
  }
  Eigen::Vector3f point(int u, int v, float z) const {
    return {x[static_cast<std::size_t>(u)] * z, y[static_cast<std::size_t>(v)] * z, z};
  }
};

/// Level 0 is the finest (the input, or the input halved `finest_halvings` times); each further
/// level halves it again.
struct RgbdPyramid {
  std::vector<RgbdLevel> levels;
  bool empty() const { return levels.empty(); }
};

struct PyramidConfig {
  int levels = 3;
  /// Halvings of the input before level 0, per 640 pixels of width: 1 aligns a VGA frame at
  /// 320x240 (Kerl et al.'s DVO and KinectFusion's coarse levels run at or below it too).
  int finest_halvings = 1;
};

/// From depth in metres and an RGB image of one size (the colour may be empty: intensity 0,
/// geometry only). `reference` computes normals and gradients. Depths the sensor model calls out
/// of range, and the sensor's border, are left out.
RgbdPyramid build_pyramid(const std::vector<float>& depth_m, const std::vector<std::uint8_t>& rgb, const Intrinsics& K,
                          const SensorModel& sensor, const PyramidConfig& config, bool reference);

/// From an organized cloud in the camera frame (z is the depth, its colour the intensity).
RgbdPyramid build_pyramid(const Cloud& points_camera, const Intrinsics& K, const SensorModel& sensor,
                          const PyramidConfig& config, bool reference);

/// From a depth image in millimetres and its colour (a keyframe's images).
RgbdPyramid build_pyramid(const DepthImage& depth, const ColorImage& color, const Intrinsics& K,
                          const SensorModel& sensor, const PyramidConfig& config, bool reference);

}  // namespace scenewatch::localization
