#pragma once
// The voxels of a VoxelIndex grouped in columns along the grid's third axis, for neighbourhood
// queries: the voxels within `reach` of a voxel take one hash lookup per column (25 at reach 2)
// instead of one per cell (125). Camera-frame clouds hold few voxels per column (the third axis
// is depth), so scanning a column's short list costs little.
#include <tsl/robin_map.h>

#include <array>
#include <cstdint>
#include <vector>

#include "voxel_index.h"

namespace scenewatch::segmentation {

class VoxelColumns {
 public:
  explicit VoxelColumns(const VoxelIndex& grid);

  /// Calls f(w, dx, dy, dz) for every voxel w with |dx|, |dy|, |dz| <= reach from coords c
  /// (c itself included).
  template <typename F>
  void for_each_near(const std::array<int, 3>& c, int reach, F&& f) const {
    for (int dx = -reach; dx <= reach; ++dx)
      for (int dy = -reach; dy <= reach; ++dy) {
        const auto it = columns_.find(pack(c[0] + dx, c[1] + dy));
        if (it == columns_.end()) continue;
        for (int k = offsets_[it->second]; k < offsets_[it->second + 1]; ++k) {
          const int dz = entries_[k].z - c[2];
          if (dz >= -reach && dz <= reach) f(entries_[k].voxel, dx, dy, dz);
        }
      }
  }

 private:
  struct Entry {
    int z;
    int voxel;
  };
  static std::uint64_t pack(int x, int y) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
  }
  tsl::robin_map<std::uint64_t, int, MixHash64> columns_;  ///< (x, y) -> column
  std::vector<int> offsets_;                               ///< CSR: entries of column c are [offsets_[c], offsets_[c + 1])
  std::vector<Entry> entries_;
};

}  // namespace scenewatch::segmentation
