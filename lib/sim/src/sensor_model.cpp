#include "scenewatch/sim/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "random.h"

namespace scenewatch::sim {
namespace {

constexpr std::uint64_t kStreamPixels = 1;
constexpr std::uint64_t kStreamPose = 3;
constexpr double kDegToRad = M_PI / 180.0;

/// Rounds a colour value to 0..255 without a libm call.
std::uint8_t to_byte(float v) {
  if (v <= 0.0f) return 0;
  if (v >= 255.0f) return 255;
  return static_cast<std::uint8_t>(v + 0.5f);
}

}  // namespace

SensorModel::SensorModel(SensorConfig config, std::uint64_t seed) : config_(config), seed_(seed) {}

double SensorModel::depth_sigma_m(double z) const {
  const double dz = z - config_.depth_sigma_offset_m;
  return config_.depth_sigma_base_m + config_.depth_sigma_quad * dz * dz;
}

double SensorModel::quantization_step_m(double z, double fx) const {
  if (!config_.noise || config_.disparity_step_px <= 0 || config_.baseline_m <= 0) return 0.0;
  return z * z * config_.disparity_step_px / (fx * config_.baseline_m);
}

void SensorModel::apply(const IdealView& view, double fx, std::uint64_t frame_key, ColorImage* color,
                        DepthImage* depth) const {
  const std::size_t n = static_cast<std::size_t>(view.width) * view.height;
  color->width = depth->width = view.width;
  color->height = depth->height = view.height;
  color->rgb.resize(3 * n);
  depth->depth_mm.assign(n, DepthImage::kInvalid);

  // Locals and raw pointers: the byte stores below may alias anything, so nothing the loops read
  // should live behind a pointer the compiler has to reload.
  const SensorConfig c = config_;
  const double cos_start = std::cos(c.grazing_start_deg * kDegToRad);
  const double cos_end = std::cos(c.grazing_end_deg * kDegToRad);
  const double start_rad = c.grazing_start_deg * kDegToRad;
  const double inv_band_rad = 1.0 / ((c.grazing_end_deg - c.grazing_start_deg) * kDegToRad);
  const bool quantize = c.noise && c.disparity_step_px > 0 && c.baseline_m > 0;
  const float* gauss = detail::gaussian_table();
  const std::uint64_t pixel_key = detail::hash(seed_, kStreamPixels, frame_key, 0);
  constexpr std::uint64_t kMask = 0x3FFF;
  const bool color_noise = c.noise && c.color_sigma > 0;
  const float color_sigma = static_cast<float>(c.color_sigma);
  const bool hole_on_glass = c.transparent_depth == TransparentDepth::kHole;

  // Disparity quantization: disparity levels k (in steps) map to depths fb_step / k; a table of
  // those depths replaces the second division.
  const double fb_step = quantize ? fx * c.baseline_m / c.disparity_step_px : 0.0;
  std::vector<double> level_depth;
  if (quantize) {
    const auto levels = static_cast<std::size_t>(fb_step / std::max(c.min_depth_m * 0.5, 0.05)) + 2;
    level_depth.resize(levels);
    level_depth[0] = fb_step;  // k is at least 1
    for (std::size_t k = 1; k < levels; ++k) level_depth[k] = fb_step / static_cast<double>(k);
  }

  const float* rgb_in = view.rgb.data();
  const float* depth_in = view.depth_m.data();
  const float* opaque_in = view.opaque_depth_m.data();
  const float* cos_in = view.cos_incidence.data();
  const float* opaque_cos_in = view.opaque_cos_incidence.data();
  const std::uint8_t* glass_in = view.transparent.data();
  std::uint8_t* rgb_out = color->rgb.data();
  std::uint16_t* mm_out = depth->depth_mm.data();

  // One 64-bit draw per pixel: 3 x 14 bits of colour noise, 14 bits of depth noise, 8 bits for
  // the grazing-angle holes.
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t bits = detail::stream_bits(pixel_key, i);
    // Colour.
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const float noise = color_noise ? color_sigma * gauss[(bits >> (14 * ch)) & kMask] : 0.0f;
      rgb_out[3 * i + ch] = to_byte(rgb_in[3 * i + ch] + noise);
    }

    // Depth.
    double z = depth_in[i];
    double cos_inc = cos_in[i];
    if (glass_in[i]) {
      if (hole_on_glass) continue;
      z = opaque_in[i];  // the sensor sees through the glass
      cos_inc = opaque_cos_in[i];
    }
    if (!(z >= c.min_depth_m && z <= c.max_depth_m)) continue;  // also rejects inf and NaN
    if (cos_inc < cos_start) {
      if (cos_inc <= cos_end) continue;
      if (c.noise) {
        // The share of holes grows linearly with the angle between start and end.
        const double p_hole = (std::acos(cos_inc) - start_rad) * inv_band_rad;
        if (static_cast<double>(bits >> 56) * (1.0 / 256.0) < p_hole) continue;
      }
    }
    if (c.noise) {
      const double dz = z - c.depth_sigma_offset_m;
      z += (c.depth_sigma_base_m + c.depth_sigma_quad * dz * dz) * gauss[(bits >> 42) & kMask];
      if (quantize && z > 0.0) {
        const auto k = static_cast<std::size_t>(fb_step / z + 0.5);
        z = k < level_depth.size() ? level_depth[k] : fb_step / static_cast<double>(k);
      }
    }
    if (!(z > 0.0) || z * 1000.0 >= 65534.5) continue;
    const long mm = static_cast<long>(z * 1000.0 + 0.5);
    if (mm <= 0) continue;
    mm_out[i] = static_cast<std::uint16_t>(mm);
  }
}

Pose SensorModel::reported_pose(const Pose& T_world_camera, std::uint64_t frame_key) const {
  if (config_.pose_sigma_m <= 0 && config_.pose_sigma_deg <= 0) return T_world_camera;
  Eigen::Vector3d dt, dr;
  for (int k = 0; k < 3; ++k) {
    dt[k] = config_.pose_sigma_m * detail::gaussian14(detail::hash(seed_, kStreamPose, frame_key, k));
    dr[k] = config_.pose_sigma_deg * kDegToRad * detail::gaussian14(detail::hash(seed_, kStreamPose, frame_key, 3 + k));
  }
  Pose delta = Pose::Identity();
  if (dr.norm() > 0) delta.linear() = Eigen::AngleAxisd(dr.norm(), dr.normalized()).toRotationMatrix();
  delta.translation() = dt;
  return T_world_camera * delta;
}

}  // namespace scenewatch::sim
