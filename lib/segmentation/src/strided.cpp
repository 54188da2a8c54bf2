// Segmentation of an organized cloud on every stride-th pixel and row, carried back to every pixel.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::segmentation {
namespace {

// Every stride-th pixel of every stride-th row, as an organized cloud; samples farther than
// max_range_m from the sensor (when > 0) left out (NaN).
Cloud decimate(const Cloud& cloud, int stride, const Eigen::Vector3d& sensor_origin, double max_range_m) {
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  Cloud samples;
  samples.width = static_cast<std::uint32_t>((w + stride - 1) / stride);
  samples.height = static_cast<std::uint32_t>((h + stride - 1) / stride);
  samples.is_dense = false;
  samples.points.reserve(static_cast<std::size_t>(samples.width) * samples.height);
  for (int v = 0; v < h; v += stride)
    for (int u = 0; u < w; u += stride) samples.points.push_back(cloud.points[static_cast<std::size_t>(v) * w + u]);
  if (max_range_m > 0) {
    const Eigen::Vector3f origin = sensor_origin.cast<float>();
    const auto range2 = static_cast<float>(max_range_m * max_range_m);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (PointT& p : samples.points)
      if (is_valid(p) && (p.getVector3fMap() - origin).squaredNorm() > range2) p.x = p.y = p.z = nan;
  }
  return samples;
}

// Full-resolution members of each labelled sample set: each pixel takes the label of the nearest
// valid sample among the (up to) four around it, when that sample lies within `reach_m`. The
// pixels of a block (the stride x stride pixels whose top-left sample is the block's) share their
// four samples, so blocks without a labelled corner are passed over: on a room frame objects
// cover a small part of the image. Rows in order, so each member list comes out sorted.
std::vector<std::vector<int>> upsample(const Cloud& cloud, const std::vector<int>& label_of_sample, std::size_t labels,
                                       int stride, double reach_m) {
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  const int sw = (w + stride - 1) / stride, sh = (h + stride - 1) / stride;
  const auto reach2 = static_cast<float>(reach_m * reach_m);
  auto corner = [&](int su, int sv, int k) {
    const int cu = su + (k & 1), cv = sv + (k >> 1);
    return cu < sw && cv < sh ? cv * sw + cu : -1;
  };
  std::vector<char> labelled_block(static_cast<std::size_t>(sw) * sh, 0);
  for (int sv = 0; sv < sh; ++sv)
    for (int su = 0; su < sw; ++su)
      for (int k = 0; k < 4; ++k) {
        const int s = corner(su, sv, k);
        if (s >= 0 && label_of_sample[s] >= 0) labelled_block[static_cast<std::size_t>(sv) * sw + su] = 1;
      }
  std::vector<std::vector<int>> members(labels);
  for (int v = 0; v < h; ++v) {
    const int sv = v / stride;
    for (int su = 0; su < sw; ++su) {
      if (!labelled_block[static_cast<std::size_t>(sv) * sw + su]) continue;
      const std::array<int, 4> around{corner(su, sv, 0), corner(su, sv, 1), corner(su, sv, 2), corner(su, sv, 3)};
      for (int u = su * stride; u < std::min(w, (su + 1) * stride); ++u) {
        const PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
        if (!is_valid(p)) continue;
        float best = std::numeric_limits<float>::infinity();
        int label = -1;
        for (int s : around) {
          if (s < 0) continue;
          const PointT& q = cloud.points[static_cast<std::size_t>(s / sw * stride) * w + (s % sw) * stride];
          if (!is_valid(q)) continue;
          const float d2 = (q.getVector3fMap() - p.getVector3fMap()).squaredNorm();
          if (d2 < best) {
            best = d2;
            label = label_of_sample[s];
          }
        }
        if (label >= 0 && best <= reach2) members[label].push_back(v * w + u);
      }
    }
  }
  return members;
}

}  // namespace

Segmentation segment_strided(const Cloud& cloud, const Config& config, const Eigen::Vector3d& sensor_origin, int stride,
                             double max_range_m) {
  if (cloud.height <= 1 || stride <= 1) return segment(cloud, config, sensor_origin);
  // The same least surface: a sample stands for stride^2 pixels.
  Config sampled = config;
  const int area = stride * stride;
  sampled.min_cluster_points = std::max(1, config.min_cluster_points / area);
  sampled.max_cluster_points = std::max(sampled.min_cluster_points, config.max_cluster_points / area);
  const Cloud samples = decimate(cloud, stride, sensor_origin, max_range_m);
  Segmentation out = segment(samples, sampled, sensor_origin);

  // Each pixel of an object takes the object of its nearest sample (objects are what a user asks
  // for by point); a plane keeps the pixels of its samples' blocks that lie on it. Counts and
  // indices are then those of the full cloud; shapes, boxes and colours stay the samples'.
  std::vector<int> label(samples.size(), -1);
  for (std::size_t o = 0; o < out.objects.size(); ++o)
    for (int s : out.objects[o].indices) label[s] = static_cast<int>(o);
  std::vector<std::vector<int>> members = upsample(cloud, label, out.objects.size(), stride, config.voxel_size_m);
  for (std::size_t o = 0; o < out.objects.size(); ++o) {
    out.objects[o].indices = std::move(members[o]);
    out.objects[o].point_count = out.objects[o].indices.size();
  }
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height), sw = static_cast<int>(samples.width);
  for (Plane& plane : out.planes) {
    // The samples row by row (make_plane lists them in index order), and each row of samples
    // pixel row by pixel row: the pixels come out in index order without a sort.
    if (!std::is_sorted(plane.indices.begin(), plane.indices.end())) std::sort(plane.indices.begin(), plane.indices.end());
    std::vector<int> pixels;
    pixels.reserve(plane.indices.size() * static_cast<std::size_t>(area));
    for (auto row = plane.indices.begin(); row != plane.indices.end();) {
      const int sv = *row / sw;
      const auto row_end = std::find_if(row, plane.indices.end(), [&](int s) { return s / sw != sv; });
      for (int v = sv * stride; v < std::min(h, (sv + 1) * stride); ++v)
        for (auto s = row; s != row_end; ++s) {
          const int u0 = *s % sw * stride;
          for (int u = u0; u < std::min(w, u0 + stride); ++u) {
            const PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
            if (is_valid(p) && std::abs(plane.signed_distance(p.getVector3fMap().cast<double>())) <= config.plane_distance_m)
              pixels.push_back(v * w + u);
          }
        }
      row = row_end;
    }
    plane.indices = std::move(pixels);
    plane.inlier_count = plane.indices.size();
  }
  return out;
}

}  // namespace scenewatch::segmentation
