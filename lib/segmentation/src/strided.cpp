// Segmentation of an organized cloud on every stride-th pixel and row, carried back to every pixel.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::segmentation {
namespace {

// Every stride-th pixel of every stride-th row, as an organized cloud.
Cloud decimate(const Cloud& cloud, int stride) {
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  Cloud samples;
  samples.width = static_cast<std::uint32_t>((w + stride - 1) / stride);
  samples.height = static_cast<std::uint32_t>((h + stride - 1) / stride);
  samples.is_dense = false;
  samples.points.reserve(static_cast<std::size_t>(samples.width) * samples.height);
  for (int v = 0; v < h; v += stride)
    for (int u = 0; u < w; u += stride) samples.points.push_back(cloud.points[static_cast<std::size_t>(v) * w + u]);
  return samples;
}

// The pixel grid of the samples over the full-resolution cloud: each pixel takes the label of the
// nearest valid sample among the (up to) four around it, when that sample lies within `reach_m`.
class Upsampler {
 public:
  Upsampler(const Cloud& cloud, const std::vector<int>& label_of_sample, int stride, double reach_m)
      : cloud_(cloud), label_(label_of_sample), stride_(stride), w_(static_cast<int>(cloud.width)),
        h_(static_cast<int>(cloud.height)), sw_((w_ + stride - 1) / stride), sh_((h_ + stride - 1) / stride),
        reach2_(static_cast<float>(reach_m * reach_m)) {}

  // The full-resolution points of label `l` whose samples are `samples` (sample indices),
  // ascending. Only the pixels around those samples are visited.
  std::vector<int> members(const std::vector<int>& samples, int l) const {
    int su0 = sw_, su1 = -1, sv0 = sh_, sv1 = -1;
    for (int s : samples) {
      su0 = std::min(su0, s % sw_);
      su1 = std::max(su1, s % sw_);
      sv0 = std::min(sv0, s / sw_);
      sv1 = std::max(sv1, s / sw_);
    }
    std::vector<int> out;
    out.reserve(samples.size() * static_cast<std::size_t>(stride_ * stride_));
    for (int v = std::max(0, (sv0 - 1) * stride_); v <= std::min(h_ - 1, (sv1 + 1) * stride_); ++v)
      for (int u = std::max(0, (su0 - 1) * stride_); u <= std::min(w_ - 1, (su1 + 1) * stride_); ++u)
        if (nearest_label(u, v, l) == l) out.push_back(v * w_ + u);
    return out;
  }

 private:
  // The label of the nearest valid sample around pixel (u, v) within reach, or -1; returns -1 at
  // once when no sample around carries `hint` (most of a bounding box).
  int nearest_label(int u, int v, int hint) const {
    std::array<int, 4> around{-1, -1, -1, -1};
    bool any = false;
    for (int k = 0; k < 4; ++k) {
      const int su = u / stride_ + (k & 1), sv = v / stride_ + (k >> 1);
      if (su >= sw_ || sv >= sh_) continue;
      around[k] = sv * sw_ + su;
      any = any || label_[around[k]] == hint;
    }
    const PointT& p = cloud_.points[static_cast<std::size_t>(v) * w_ + u];
    if (!any || !is_valid(p)) return -1;
    float best = std::numeric_limits<float>::infinity();
    int label = -1;
    for (int s : around) {
      if (s < 0) continue;
      const PointT& q = cloud_.points[static_cast<std::size_t>(s / sw_ * stride_) * w_ + (s % sw_) * stride_];
      if (!is_valid(q)) continue;
      const float d2 = (q.getVector3fMap() - p.getVector3fMap()).squaredNorm();
      if (d2 < best) {
        best = d2;
        label = label_[s];
      }
    }
    return best <= reach2_ ? label : -1;
  }

  const Cloud& cloud_;
  const std::vector<int>& label_;
  int stride_, w_, h_, sw_, sh_;
  float reach2_;
};

}  // namespace

Segmentation segment_strided(const Cloud& cloud, const Config& config, const Eigen::Vector3d& sensor_origin, int stride) {
  if (cloud.height <= 1 || stride <= 1) return segment(cloud, config, sensor_origin);
  // The same least surface: a sample stands for stride^2 pixels.
  Config sampled = config;
  const int area = stride * stride;
  sampled.min_cluster_points = std::max(1, config.min_cluster_points / area);
  sampled.max_cluster_points = std::max(sampled.min_cluster_points, config.max_cluster_points / area);
  const Cloud samples = decimate(cloud, stride);
  Segmentation out = segment(samples, sampled, sensor_origin);

  // Each pixel of an object takes the object of its nearest sample (objects are what a user asks
  // for by point); a plane keeps the pixels of its samples' blocks that lie on it. Counts and
  // indices are then those of the full cloud; shapes, boxes and colours stay the samples'.
  std::vector<int> label(samples.size(), -1);
  for (std::size_t o = 0; o < out.objects.size(); ++o)
    for (int s : out.objects[o].indices) label[s] = static_cast<int>(o);
  const Upsampler up(cloud, label, stride, config.voxel_size_m);
  for (std::size_t o = 0; o < out.objects.size(); ++o) {
    ObjectCluster& object = out.objects[o];
    object.indices = up.members(object.indices, static_cast<int>(o));
    object.point_count = object.indices.size();
  }
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height), sw = static_cast<int>(samples.width);
  for (Plane& plane : out.planes) {
    std::vector<int> pixels;
    pixels.reserve(plane.indices.size() * static_cast<std::size_t>(area));
    for (int s : plane.indices) {
      const int u0 = s % sw * stride, v0 = s / sw * stride;
      for (int v = v0; v < std::min(h, v0 + stride); ++v)
        for (int u = u0; u < std::min(w, u0 + stride); ++u) {
          const PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
          if (is_valid(p) && std::abs(plane.signed_distance(p.getVector3fMap().cast<double>())) <= config.plane_distance_m)
            pixels.push_back(v * w + u);
        }
    }
    std::sort(pixels.begin(), pixels.end());
    plane.indices = std::move(pixels);
    plane.inlier_count = plane.indices.size();
  }
  return out;
}

}  // namespace scenewatch::segmentation
