#include "voxel_columns.h"

#include <algorithm>

namespace scenewatch::segmentation {

VoxelColumns::VoxelColumns(const VoxelIndex& grid) {
  const std::size_t n = grid.coords.size();
  columns_.reserve(n / 2 + 16);
  std::vector<int> column_of(n);
  for (std::size_t v = 0; v < n; ++v) {
    const auto& c = grid.coords[v];
    const auto [it, inserted] = columns_.try_emplace(pack(c[0], c[1]), static_cast<int>(offsets_.size()));
    if (inserted) {
      offsets_.push_back(0);
      xy_.push_back({c[0], c[1]});
    }
    column_of[v] = it->second;
    ++offsets_[it->second];
  }
  // Counts become offsets; voxels enter their column in index order, then go in order of z.
  offsets_.push_back(0);
  int running = 0;
  for (int& o : offsets_) {
    const int count = o;
    o = running;
    running += count;
  }
  entries_.resize(n);
  std::vector<int> fill(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t v = 0; v < n; ++v) entries_[fill[column_of[v]]++] = {grid.coords[v][2], static_cast<int>(v)};
  for (std::size_t c = 0; c < xy_.size(); ++c)
    std::sort(entries_.begin() + offsets_[c], entries_.begin() + offsets_[c + 1],
              [](const Entry& a, const Entry& b) { return a.z < b.z || (a.z == b.z && a.voxel < b.voxel); });
}

}  // namespace scenewatch::segmentation
