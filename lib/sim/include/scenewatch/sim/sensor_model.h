#pragma once
/// A Kinect-like RGB-D sensor: turns ideal images into the colour and 16-bit depth a real sensor
/// would deliver. Depth noise grows with z^2 (Nguyen et al. 2012, sigma = a + b (z - z0)^2),
/// depth is quantized in disparity (1/8 pixel on a 7.5 cm baseline) and then to millimetres,
/// surfaces seen at grazing angles and glass give holes, colour gets Gaussian noise, the reported
/// pose optional noise. Every draw is a hash of (seed, frame, pixel): reproducible to the byte.
#include <cstdint>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/sim/raycaster.h"

namespace scenewatch::sim {

/// What a depth sensor returns on glass.
enum class TransparentDepth {
  kHole,    ///< no depth (the usual Kinect behaviour on clear glass)
  kBehind,  ///< the depth of the surface behind the glass (a wrong depth)
};

/// Sensor parameters; defaults model a Kinect v1.
struct SensorConfig {
  bool noise = true;                    ///< false: exact depth (rounded to mm), exact colour
  double depth_sigma_base_m = 0.0012;   ///< sigma at z = depth_sigma_offset_m
  double depth_sigma_quad = 0.0019;     ///< growth of sigma per (z - offset)^2, 1/m
  double depth_sigma_offset_m = 0.4;
  double baseline_m = 0.075;            ///< projector-camera baseline for disparity quantization
  double disparity_step_px = 0.125;     ///< 0: no disparity quantization (only millimetres)
  double min_depth_m = 0.4;             ///< nearer than this: no depth
  double max_depth_m = 4.5;             ///< farther than this: no depth
  double grazing_start_deg = 72.0;      ///< holes start to appear beyond this incidence angle
  double grazing_end_deg = 84.0;        ///< and are certain beyond this one
  TransparentDepth transparent_depth = TransparentDepth::kHole;
  double color_sigma = 2.0;             ///< colour noise per channel, 0..255 units
  double pose_sigma_m = 0.0;            ///< noise of the reported (written) camera position
  double pose_sigma_deg = 0.0;          ///< noise of the reported camera orientation
};

/// Applies a SensorConfig. Stateless after construction: thread safe.
class SensorModel {
 public:
  /// A sensor with the given parameters and random seed.
  SensorModel(SensorConfig config, std::uint64_t seed);

  /// Standard deviation of the depth noise at depth z.
  double depth_sigma_m(double z_m) const;
  /// Depth step of the disparity quantization at depth z for focal length fx (0 when off).
  double quantization_step_m(double z_m, double fx) const;

  /// Degrades an ideal view into sensor images; frame_key selects the random stream (a frame
  /// index that is unique within the run).
  void apply(const IdealView& view, double fx, std::uint64_t frame_key, ColorImage* color, DepthImage* depth) const;

  /// The camera pose the sensor reports for a true pose (the true pose when pose noise is 0).
  Pose reported_pose(const Pose& T_world_camera, std::uint64_t frame_key) const;

  /// The parameters.
  const SensorConfig& config() const { return config_; }

 private:
  SensorConfig config_;
  std::uint64_t seed_;
};

}  // namespace scenewatch::sim
