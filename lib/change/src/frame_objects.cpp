// The segmented objects of a frame by point, the segmentation run on a decimated organized cloud.
#include "scenewatch/change/frame_objects.h"

#include <algorithm>
#include <array>
#include <limits>

namespace scenewatch::change {
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

// Full-resolution labels from the samples' labels: each point takes the object of the nearest
// of the (up to) four samples around its pixel, when within `reach_m`. Only the pixels around an
// object's samples are visited, so the cost follows the objects' area, not the frame's.
class Upsampler {
 public:
  Upsampler(const Cloud& cloud, const ObjectLabels& coarse, int stride, double reach_m)
      : cloud_(cloud), coarse_(coarse), stride_(stride), w_(static_cast<int>(cloud.width)), h_(static_cast<int>(cloud.height)),
        sw_((w_ + stride - 1) / stride), sh_((h_ + stride - 1) / stride), reach2_(static_cast<float>(reach_m * reach_m)) {}

  // The full-resolution points of coarse object o, ascending.
  std::vector<int> members(int o) const {
    int su0 = sw_, su1 = -1, sv0 = sh_, sv1 = -1;
    for (int s : coarse_.members[o]) {
      su0 = std::min(su0, s % sw_);
      su1 = std::max(su1, s % sw_);
      sv0 = std::min(sv0, s / sw_);
      sv1 = std::max(sv1, s / sw_);
    }
    std::vector<int> out;
    for (int v = std::max(0, (sv0 - 1) * stride_); v <= std::min(h_ - 1, (sv1 + 1) * stride_); ++v)
      for (int u = std::max(0, (su0 - 1) * stride_); u <= std::min(w_ - 1, (su1 + 1) * stride_); ++u) {
        if (near_object(u, v, o)) out.push_back(v * w_ + u);
      }
    return out;
  }

 private:
  // True when the nearest valid sample around pixel (u, v) belongs to object o and lies within
  // reach. Pixels with no sample of o around them (most of a bounding box) return at once.
  bool near_object(int u, int v, int o) const {
    std::array<int, 4> samples{-1, -1, -1, -1};
    bool any = false;
    for (int k = 0; k < 4; ++k) {
      const int su = u / stride_ + (k & 1), sv = v / stride_ + (k >> 1);
      if (su >= sw_ || sv >= sh_) continue;
      samples[k] = sv * sw_ + su;
      any = any || coarse_.object_of[samples[k]] == o;
    }
    const PointT& p = cloud_.points[static_cast<std::size_t>(v) * w_ + u];
    if (!any || !is_valid(p)) return false;
    float best = std::numeric_limits<float>::infinity();
    int object = -1;
    for (int s : samples) {
      if (s < 0) continue;
      const PointT& q = cloud_.points[static_cast<std::size_t>(s / sw_ * stride_) * w_ + (s % sw_) * stride_];
      if (!is_valid(q)) continue;
      const float d2 = (q.getVector3fMap() - p.getVector3fMap()).squaredNorm();
      if (d2 < best) {
        best = d2;
        object = coarse_.object_of[s];
      }
    }
    return object == o && best <= reach2_;
  }

  const Cloud& cloud_;
  const ObjectLabels& coarse_;
  int stride_, w_, h_, sw_, sh_;
  float reach2_;
};

}  // namespace

ObjectLabels label_objects(const segmentation::Segmentation& segmentation, std::size_t cloud_size) {
  ObjectLabels labels;
  labels.object_of.assign(cloud_size, -1);
  for (const auto& object : segmentation.objects) {
    const int id = static_cast<int>(labels.members.size());
    for (int i : object.indices) labels.object_of[i] = id;
    labels.members.push_back(object.indices);
  }
  return labels;
}

ObjectLabels segment_objects(const Cloud& cloud, const segmentation::Config& config, int stride) {
  if (cloud.height <= 1 || stride <= 1) return label_objects(segmentation::segment(cloud, config), cloud.size());
  // The same least surface: a sample stands for stride^2 pixels.
  segmentation::Config sampled = config;
  const int area = stride * stride;
  sampled.min_cluster_points = std::max(1, config.min_cluster_points / area);
  sampled.max_cluster_points = std::max(sampled.min_cluster_points, config.max_cluster_points / area);
  const Cloud samples = decimate(cloud, stride);
  const ObjectLabels coarse = label_objects(segmentation::segment(samples, sampled), samples.size());
  const Upsampler up(cloud, coarse, stride, config.voxel_size_m);
  ObjectLabels out;
  out.object_of.assign(cloud.size(), -1);
  for (std::size_t o = 0; o < coarse.members.size(); ++o) {
    std::vector<int> m = up.members(static_cast<int>(o));
    for (int i : m) out.object_of[i] = static_cast<int>(o);
    out.members.push_back(std::move(m));
  }
  return out;
}

}  // namespace scenewatch::change
