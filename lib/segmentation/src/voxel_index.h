#pragma once
// A sparse voxel grid over a cloud: one centroid per occupied voxel and, for every input point,
// the voxel it fell in. Segmentation works on voxels and maps results back to points.
#include <tsl/robin_map.h>

#include <array>
#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::segmentation {

struct VoxelIndex {
  /// Builds the grid of the valid points of `cloud` at edge `voxel_size_m`.
  VoxelIndex(const Cloud& cloud, double voxel_size_m);
  /// The same over the points `indices` of `cloud` only; it costs the subset's size, so
  /// point_voxel is left empty (use the members of each voxel).
  VoxelIndex(const Cloud& cloud, const std::vector<int>& indices, double voxel_size_m);

  /// Voxel index at integer coordinates, or -1.
  int find(int x, int y, int z) const {
    auto it = lookup.find(pack(x, y, z));
    return it == lookup.end() ? -1 : it->second;
  }

  double size;
  std::vector<Eigen::Vector3f> centroids;
  std::vector<std::array<int, 3>> coords;   ///< integer voxel coordinates
  std::vector<int> point_voxel;             ///< per input point, -1 for invalid ones (whole-cloud grids only)
  std::vector<int> member_offsets;          ///< CSR: points of voxel v are member_points[offsets[v]..offsets[v+1])
  std::vector<int> member_points;
  int member_count(int v) const { return member_offsets[v + 1] - member_offsets[v]; }
  const int* members_begin(int v) const { return member_points.data() + member_offsets[v]; }
  const int* members_end(int v) const { return member_points.data() + member_offsets[v + 1]; }

 private:
  /// Fills the grid; returns the voxel of each visited point in visiting order (-1: invalid).
  template <typename ForEachIndex>
  std::vector<int> build(const Cloud& cloud, ForEachIndex&& for_each_index);
  static std::uint64_t pack(int x, int y, int z) {
    constexpr std::uint64_t kMask = (1u << 21) - 1;  // +-1M voxels per axis
    return ((static_cast<std::uint64_t>(x + (1 << 20)) & kMask) << 42) |
           ((static_cast<std::uint64_t>(y + (1 << 20)) & kMask) << 21) |
           (static_cast<std::uint64_t>(z + (1 << 20)) & kMask);
  }
  tsl::robin_map<std::uint64_t, int, MixHash64> lookup;
};

/// The 13 forward offsets of the 26-neighbourhood: each unordered pair of neighbouring voxels once.
const std::vector<std::array<int, 3>>& forward_offsets();

}  // namespace scenewatch::segmentation
