#include "voxel_columns.h"

#include <algorithm>

namespace scenewatch::segmentation {

VoxelColumns::VoxelColumns(const VoxelIndex& grid) {
  const std::size_t n = grid.coords.size();
  std::vector<int> column_of(n);
  int x1 = n == 0 ? 0 : grid.coords[0][0], y1 = n == 0 ? 0 : grid.coords[0][1];
  x0_ = x1, y0_ = y1;
  for (const auto& c : grid.coords) {
    x0_ = std::min(x0_, c[0]), x1 = std::max(x1, c[0]);
    y0_ = std::min(y0_, c[1]), y1 = std::max(y1, c[1]);
  }
  const std::size_t cells = n == 0 ? 0 : (static_cast<std::size_t>(x1 - x0_) + 1) * (static_cast<std::size_t>(y1 - y0_) + 1);
  if (n > 0 && cells <= std::max<std::size_t>(std::size_t{1} << 20, 8 * n)) {
    nx_ = static_cast<unsigned>(x1 - x0_) + 1, ny_ = static_cast<unsigned>(y1 - y0_) + 1;
    dense_.assign(cells, -1);
  } else {
    columns_.reserve(n / 2 + 16);
  }
  // Columns are numbered in the order their first voxel comes, either way.
  for (std::size_t v = 0; v < n; ++v) {
    const auto& c = grid.coords[v];
    int* slot = nullptr;
    if (!dense_.empty()) {
      slot = &dense_[static_cast<std::size_t>(c[0] - x0_) * ny_ + static_cast<std::size_t>(c[1] - y0_)];
    } else {
      slot = &columns_.try_emplace(pack(c[0], c[1]), -1).first.value();
    }
    if (*slot < 0) {
      *slot = static_cast<int>(offsets_.size());
      offsets_.push_back(0);
      xy_.push_back({c[0], c[1]});
    }
    column_of[v] = *slot;
    ++offsets_[static_cast<std::size_t>(*slot)];
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
