#include "scenewatch/change/surface_witness.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace scenewatch::change {

SurfaceWitness::SurfaceWitness(double voxel_m, std::size_t max_voxels) : per_m_(1.0 / voxel_m), max_voxels_(max_voxels) {}

std::uint64_t SurfaceWitness::key(const Eigen::Vector3d& p) const {
  // 21 bits per axis around the origin: +-20 km at 2 cm.
  auto c = [&](double x) { return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(x * per_m_)) + (1 << 20)) & 0x1fffff; };
  return (c(p.x()) << 42) | (c(p.y()) << 21) | c(p.z());
}

void SurfaceWitness::witness(const Cloud& cloud, const Pose& T, std::uint32_t camera, int stride) {
  ++frame_;
  const std::uint64_t bit = std::uint64_t{1} << (camera % 64);
  const Eigen::Isometry3f Tf = T.cast<float>();
  // Neighbouring pixels mostly fall in one voxel (a 2 cm voxel spans 5 pixels at 2 m), in this
  // row and in the rows above: marking it again, at no smaller depth, changes nothing. A small
  // table of the voxels marked in this frame (direct-mapped by key, with the depth marked) spares
  // most of the lookups in the map.
  if (recent_.empty()) recent_.resize(kRecent);
  auto add = [&](const PointT& p) {
    if (!is_valid(p)) return;
    const std::uint64_t k = key((Tf * p.getVector3fMap()).cast<double>());
    Recent& r = recent_[(k ^ (k >> 19) ^ (k >> 40)) & (kRecent - 1)];  // the low bits of each axis
    if (r.frame == frame_ && r.key == k && p.z >= r.depth_m) return;
    r = {k, frame_, p.z};
    Entry& e = voxels_[k];
    e.cameras |= bit;
    e.last_frame = frame_;
    if (e.nearest_depth_m == 0.0f || p.z < e.nearest_depth_m) e.nearest_depth_m = p.z;
  };
  if (cloud.height > 1 && stride > 1) {
    for (std::uint32_t v = 0; v < cloud.height; v += static_cast<std::uint32_t>(stride))
      for (std::uint32_t u = 0; u < cloud.width; u += static_cast<std::uint32_t>(stride)) add(cloud.points[v * cloud.width + u]);
  } else {
    for (const auto& p : cloud.points) add(p);
  }
  if (voxels_.size() > max_voxels_) prune();
}

SurfaceWitness::Seen SurfaceWitness::seen(const Eigen::Vector3d& p, std::uint32_t camera, double* nearest_depth_m) const {
  const auto it = voxels_.find(key(p));
  if (nearest_depth_m != nullptr) *nearest_depth_m = it == voxels_.end() ? 0.0 : it->second.nearest_depth_m;
  if (it == voxels_.end()) return Seen::kByNone;
  return (it->second.cameras & (std::uint64_t{1} << (camera % 64))) != 0 ? Seen::kBySelf : Seen::kByOthersOnly;
}

void SurfaceWitness::forget(const std::vector<Eigen::Vector3d>& points) {
  for (const auto& p : points) voxels_.erase(key(p));
}

// Keeps the three quarters of the limit seen most recently.
void SurfaceWitness::prune() {
  std::vector<std::uint64_t> frames;
  frames.reserve(voxels_.size());
  for (const auto& [k, e] : voxels_) frames.push_back(e.last_frame);
  const std::size_t keep = max_voxels_ * 3 / 4;
  std::nth_element(frames.begin(), frames.end() - static_cast<long>(keep), frames.end());
  const std::uint64_t oldest_kept = *(frames.end() - static_cast<long>(keep));
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if (it->second.last_frame < oldest_kept) {
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace scenewatch::change
