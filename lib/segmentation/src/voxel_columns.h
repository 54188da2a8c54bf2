#pragma once
// The voxels of a VoxelIndex grouped in columns along the grid's third axis, for neighbourhood
// queries. Each column is sorted along that axis. The pairs within reach are found column by
// column: the neighbouring columns ahead of a column are looked up once for it, not once per
// voxel, and each is read through a window that slides along it as the voxels of the column rise;
// each pair is found once, from the earlier of its two columns. Looking up 25 columns for every
// voxel and meeting every pair twice took 16 ms of hrt1's 47 ms segmentation (28,000 object
// voxels); this takes 7 ms. A camera looking across a floor or a table sees long columns (the
// third axis is depth), which the windows read only where they are within reach.
#include <tsl/robin_map.h>

#include <array>
#include <cstdint>
#include <vector>

#include "voxel_index.h"

namespace scenewatch::segmentation {

class VoxelColumns {
 public:
  explicit VoxelColumns(const VoxelIndex& grid);

  /// True when columns are found through the dense table, false through the hash map.
  bool uses_table() const { return !dense_.empty(); }

  /// Calls f(a, b) once for every unordered pair of distinct voxels a, b with keep(a) and keep(b)
  /// and |dx|, |dy|, |dz| <= reach between them. The order of the pairs is unspecified.
  template <typename Keep, typename F>
  void for_each_pair(int reach, Keep&& keep, F&& f) const {
    struct Window {
      const Entry* begin;
      const Entry* end;
    };
    std::vector<Window> ahead;  // the columns after this one: dx > 0, or dx == 0 and dy > 0
    ahead.reserve(static_cast<std::size_t>((2 * reach + 1) * reach + reach));
    for (std::size_t c = 0; c < xy_.size(); ++c) {
      const Entry* first = entries_.data() + offsets_[c];
      const Entry* last = entries_.data() + offsets_[c + 1];
      ahead.clear();
      for (int dx = 0; dx <= reach; ++dx)
        for (int dy = dx == 0 ? 1 : -reach; dy <= reach; ++dy) {
          const int col = column_at(xy_[c][0] + dx, xy_[c][1] + dy);
          if (col >= 0) ahead.push_back({entries_.data() + offsets_[col], entries_.data() + offsets_[col + 1]});
        }
      for (const Entry* e = first; e != last; ++e) {
        if (!keep(e->voxel)) continue;
        // The own column: the voxels above this one (one voxel per cell, so none at the same z).
        for (const Entry* k = e + 1; k != last && k->z <= e->z + reach; ++k)
          if (keep(k->voxel)) f(e->voxel, k->voxel);
        for (Window& w : ahead) {
          while (w.begin != w.end && w.begin->z < e->z - reach) ++w.begin;  // e->z only rises
          for (const Entry* k = w.begin; k != w.end && k->z <= e->z + reach; ++k)
            if (keep(k->voxel)) f(e->voxel, k->voxel);
        }
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
  /// The column at (x, y), or -1.
  int column_at(int x, int y) const {
    if (dense_.empty()) {
      const auto it = columns_.find(pack(x, y));
      return it == columns_.end() ? -1 : it->second;
    }
    const unsigned dx = static_cast<unsigned>(x - x0_), dy = static_cast<unsigned>(y - y0_);  // wraps below the corner
    return dx < nx_ && dy < ny_ ? dense_[static_cast<std::size_t>(dx) * ny_ + dy] : -1;
  }
  // (x, y) -> column: a dense table over the columns' bounding rectangle when it is not much
  // larger than the voxels (a hash lookup per neighbouring column missed the cache: 14 % of the
  // clustering's time on the kitchen), else a hash map.
  std::vector<int> dense_;
  int x0_ = 0, y0_ = 0;
  unsigned nx_ = 0, ny_ = 0;
  tsl::robin_map<std::uint64_t, int, MixHash64> columns_;
  std::vector<std::array<int, 2>> xy_;                     ///< per column: its (x, y)
  std::vector<int> offsets_;                               ///< CSR: entries of column c are [offsets_[c], offsets_[c + 1])
  std::vector<Entry> entries_;                             ///< within a column, by z (then voxel)
};

}  // namespace scenewatch::segmentation
