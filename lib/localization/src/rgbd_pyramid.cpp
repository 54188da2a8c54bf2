// Coarse-to-fine RGB-D images for dense alignment.
#include "scenewatch/localization/rgbd_pyramid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch::localization {
namespace {

// Neighbouring depths on one surface differ by little; across a depth edge by a lot. A jump of
// more than this fraction of the depth cuts the neighbourhood (as the appearance mesh does).
constexpr float kMaxRelativeJump = 0.05f;

Intrinsics halved(const Intrinsics& K) {
  // Pixel centres: a 2x2 block's centre (2u + 0.5) maps to u.
  Intrinsics h = K;
  h.fx = K.fx / 2;
  h.fy = K.fy / 2;
  h.cx = (K.cx - 0.5) / 2;
  h.cy = (K.cy - 0.5) / 2;
  h.width = K.width / 2;
  h.height = K.height / 2;
  return h;
}

// Halves a level: depth averaged over the block's pixels on the nearest surface (a block across
// an edge takes the nearer side, never a depth between the two), intensity over all four.
RgbdLevel halve(const RgbdLevel& in) {
  RgbdLevel out;
  out.intrinsics = halved(in.intrinsics);
  out.width = out.intrinsics.width;
  out.height = out.intrinsics.height;
  out.depth_m.assign(out.pixels(), 0.0f);
  out.intensity.assign(out.pixels(), 0.0f);
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      const std::size_t i00 = static_cast<std::size_t>(2 * v) * in.width + 2 * u;
      const std::size_t idx[4] = {i00, i00 + 1, i00 + in.width, i00 + in.width + 1};
      float zmin = std::numeric_limits<float>::infinity();
      float gray = 0;
      for (std::size_t i : idx) {
        gray += in.intensity[i];
        if (in.depth_m[i] > 0) zmin = std::min(zmin, in.depth_m[i]);
      }
      const std::size_t o = static_cast<std::size_t>(v) * out.width + u;
      out.intensity[o] = gray / 4;
      if (!std::isfinite(zmin)) continue;
      float sum = 0;
      int n = 0;
      for (std::size_t i : idx) {
        if (in.depth_m[i] > 0 && in.depth_m[i] - zmin <= kMaxRelativeJump * zmin) {
          sum += in.depth_m[i];
          ++n;
        }
      }
      out.depth_m[o] = sum / n;
    }
  }
  return out;
}

bool near_in_depth(float a, float b) { return b > 0 && std::abs(a - b) <= kMaxRelativeJump * a; }

// Normals from the cross product of central differences of the back-projected points; none where
// a neighbour is missing or across a depth edge. Gradients by central differences.
void add_reference_terms(RgbdLevel& l) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  l.normals.assign(l.pixels(), Eigen::Vector3f::Constant(nan));
  l.shade.assign(l.pixels(), RgbdLevel::Shade{});
  for (std::size_t i = 0; i < l.pixels(); ++i) l.shade[i].intensity = l.intensity[i];
  const PixelRays rays(l);  // two divisions fewer in each of a pixel's five points
  for (int v = 1; v + 1 < l.height; ++v) {
    for (int u = 1; u + 1 < l.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * l.width + u;
      l.shade[i].grad_x = 0.5f * (l.intensity[i + 1] - l.intensity[i - 1]);
      l.shade[i].grad_y = 0.5f * (l.intensity[i + l.width] - l.intensity[i - l.width]);
      const float z = l.depth_m[i];
      if (z <= 0) continue;
      const float zl = l.depth_m[i - 1], zr = l.depth_m[i + 1], zu = l.depth_m[i - l.width], zd = l.depth_m[i + l.width];
      if (!near_in_depth(z, zl) || !near_in_depth(z, zr) || !near_in_depth(z, zu) || !near_in_depth(z, zd)) continue;
      const Eigen::Vector3f dx = rays.point(u + 1, v, zr) - rays.point(u - 1, v, zl);
      const Eigen::Vector3f dy = rays.point(u, v + 1, zd) - rays.point(u, v - 1, zu);
      Eigen::Vector3f n = dx.cross(dy);
      const float norm = n.norm();
      if (!(norm > 0)) continue;
      n /= norm;
      if (n.dot(rays.point(u, v, z)) > 0) n = -n;
      l.normals[i] = n;
    }
  }
}

RgbdPyramid finish(RgbdLevel full, const SensorModel& sensor, const PyramidConfig& config, bool reference) {
  // The sensor's border and out-of-range depths carry no measurement.
  const int border = std::max(0, sensor.border_px);
  for (int v = 0; v < full.height; ++v) {
    for (int u = 0; u < full.width; ++u) {
      float& z = full.depth_m[static_cast<std::size_t>(v) * full.width + u];
      const bool in_border = u < border || v < border || u >= full.width - border || v >= full.height - border;
      if (in_border || !std::isfinite(z) || !sensor.in_range(z)) z = 0;
    }
  }
  const int halvings = std::max(0, static_cast<int>(std::lround(config.finest_halvings * std::max(1.0, full.width / 640.0))));
  RgbdPyramid pyramid;
  RgbdLevel level = std::move(full);
  for (int h = 0; h < halvings && level.width >= 16 && level.height >= 16; ++h) level = halve(level);
  for (int l = 0; l < std::max(1, config.levels); ++l) {
    if (l > 0) {
      if (level.width < 16 || level.height < 16) break;
      level = halve(level);
    }
    pyramid.levels.push_back(level);
  }
  if (reference)
    for (auto& l : pyramid.levels) add_reference_terms(l);
  return pyramid;
}

RgbdLevel empty_level(const Intrinsics& K) {
  RgbdLevel l;
  l.intrinsics = K;
  l.width = K.width;
  l.height = K.height;
  l.depth_m.assign(l.pixels(), 0.0f);
  l.intensity.assign(l.pixels(), 0.0f);
  return l;
}

}  // namespace

RgbdPyramid build_pyramid(const std::vector<float>& depth_m, const std::vector<std::uint8_t>& rgb, const Intrinsics& K,
                          const SensorModel& sensor, const PyramidConfig& config, bool reference) {
  RgbdLevel l = empty_level(K);
  if (depth_m.size() != l.pixels()) return {};
  l.depth_m = depth_m;
  if (rgb.size() == 3 * l.pixels())
    for (std::size_t i = 0; i < l.pixels(); ++i)
      l.intensity[i] = (static_cast<float>(rgb[3 * i]) + rgb[3 * i + 1] + rgb[3 * i + 2]) / 765.0f;
  return finish(std::move(l), sensor, config, reference);
}

RgbdPyramid build_pyramid(const Cloud& points_camera, const Intrinsics& K, const SensorModel& sensor,
                          const PyramidConfig& config, bool reference) {
  RgbdLevel l = empty_level(K);
  if (points_camera.width != static_cast<std::uint32_t>(K.width) || points_camera.height != static_cast<std::uint32_t>(K.height))
    return {};
  for (std::size_t i = 0; i < l.pixels(); ++i) {
    const PointT& p = points_camera.points[i];
    l.intensity[i] = (static_cast<float>(p.r) + p.g + p.b) / 765.0f;
    if (is_valid(p)) l.depth_m[i] = p.z;
  }
  return finish(std::move(l), sensor, config, reference);
}

RgbdPyramid build_pyramid(const DepthImage& depth, const ColorImage& color, const Intrinsics& K,
                          const SensorModel& sensor, const PyramidConfig& config, bool reference) {
  if (depth.width != K.width || depth.height != K.height) return {};
  std::vector<float> z(depth.depth_mm.size());
  for (std::size_t i = 0; i < z.size(); ++i) {
    const std::uint16_t mm = depth.depth_mm[i];
    z[i] = (mm == 0 || mm == 65535) ? 0.0f : mm * 1e-3f;
  }
  const bool same_size = color.width == depth.width && color.height == depth.height;
  return build_pyramid(z, same_size ? color.rgb : std::vector<std::uint8_t>{}, K, sensor, config, reference);
}

}  // namespace scenewatch::localization
