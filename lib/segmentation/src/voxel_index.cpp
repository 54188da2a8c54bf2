#include "voxel_index.h"

#include <cmath>

namespace scenewatch::segmentation {

const std::vector<std::array<int, 3>>& forward_offsets() {
  static const std::vector<std::array<int, 3>> offsets = [] {
    std::vector<std::array<int, 3>> out;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx > 0 || (dx == 0 && (dy > 0 || (dy == 0 && dz > 0)))) out.push_back({dx, dy, dz});
        }
    return out;
  }();
  return offsets;
}

VoxelIndex::VoxelIndex(const Cloud& cloud, double voxel_size_m) : size(voxel_size_m) {
  lookup.reserve(cloud.size() / 8 + 16);
  // Visited in index order: the visiting order's voxels are the points' voxels.
  point_voxel = build(cloud, [&](auto&& visit) {
    for (std::size_t i = 0; i < cloud.size(); ++i) visit(i);
  });
}

VoxelIndex::VoxelIndex(const Cloud& cloud, const std::vector<int>& indices, double voxel_size_m) : size(voxel_size_m) {
  build(cloud, [&](auto&& visit) {
    for (int i : indices) visit(static_cast<std::size_t>(i));
  });
}

template <typename ForEachIndex>
std::vector<int> VoxelIndex::build(const Cloud& cloud, ForEachIndex&& for_each_index) {
  const float inv = static_cast<float>(1.0 / size);
  // The voxel of each visited point, in visiting order (-1: invalid point).
  std::vector<int> visited_voxel;
  std::vector<Eigen::Vector3f> sums;
  // Neighbouring points of an organized cloud mostly share a voxel: remember the last one and
  // skip the hash lookup when the key repeats.
  std::uint64_t last_key = ~std::uint64_t{0};
  int last_voxel = -1;
  for_each_index([&](std::size_t i) {
    const PointT& p = cloud.points[i];
    if (!is_valid(p)) {
      visited_voxel.push_back(-1);
      return;
    }
    const int x = static_cast<int>(std::floor(p.x * inv));
    const int y = static_cast<int>(std::floor(p.y * inv));
    const int z = static_cast<int>(std::floor(p.z * inv));
    const std::uint64_t key = pack(x, y, z);
    int v = last_voxel;
    if (key != last_key) {
      auto [it, inserted] = lookup.try_emplace(key, static_cast<int>(sums.size()));
      v = it->second;
      if (inserted) {
        sums.emplace_back(Eigen::Vector3f::Zero());
        coords.push_back({x, y, z});
        member_offsets.push_back(0);
      }
      last_key = key;
      last_voxel = v;
    }
    sums[v] += p.getVector3fMap();
    ++member_offsets[v];
    visited_voxel.push_back(v);
  });
  // Counting sort of the points by voxel (counts become offsets).
  const std::size_t n = sums.size();
  centroids.resize(n);
  for (std::size_t v = 0; v < n; ++v) centroids[v] = sums[v] / static_cast<float>(member_offsets[v]);
  member_offsets.push_back(0);
  int running = 0;
  for (std::size_t v = 0; v <= n; ++v) {
    const int count = member_offsets[v];
    member_offsets[v] = running;
    running += count;
  }
  member_points.resize(running);
  std::vector<int> fill(member_offsets.begin(), member_offsets.end() - 1);
  // Over the visited points only: a subset of a large cloud (one cluster) costs its own size.
  std::size_t k = 0;
  for_each_index([&](std::size_t i) {
    const int v = visited_voxel[k++];
    if (v >= 0) member_points[fill[v]++] = static_cast<int>(i);
  });
  return visited_voxel;
}

}  // namespace scenewatch::segmentation
