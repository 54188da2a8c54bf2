#include "ray_set.h"

#include <algorithm>

namespace scenewatch::background {

void RaySet::reset(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) {
  std::uint64_t volume = 1;
  for (int i = 0; i < 3; ++i) {
    lo_[i] = static_cast<octomap::key_type>(lo[i] > 0 ? lo[i] - 1 : 0);
    const std::uint32_t top = std::min<std::uint32_t>(hi[i] + 1u, 0xffffu);
    dim_[i] = top - lo_[i] + 1;
    volume *= dim_[i];
  }
  use_bitmap_ = volume <= kMaxBitmapVoxels;
  free_set_.clear();
  end_set_.clear();
  if (use_bitmap_) {
    const std::size_t words = static_cast<std::size_t>((volume + 63) / 64);
    free_bits_.assign(words, 0);
    end_bits_.assign(words, 0);
  } else {
    Bits().swap(free_bits_);
    Bits().swap(end_bits_);
  }
}

void RaySet::merge(const RaySet& other) {
  // The same bounds give the same layout (a bitmap of the same size, or hash sets).
  if (use_bitmap_) {
    for (std::size_t w = 0; w < free_bits_.size() && w < other.free_bits_.size(); ++w) {
      free_bits_[w] |= other.free_bits_[w];
      end_bits_[w] |= other.end_bits_[w];
    }
    return;
  }
  free_set_.insert(other.free_set_.begin(), other.free_set_.end());
  end_set_.insert(other.end_set_.begin(), other.end_set_.end());
}

void RaySet::clear() {
  free_set_.clear();
  end_set_.clear();
  std::fill(free_bits_.begin(), free_bits_.end(), 0);
  std::fill(end_bits_.begin(), end_bits_.end(), 0);
}

}  // namespace scenewatch::background
