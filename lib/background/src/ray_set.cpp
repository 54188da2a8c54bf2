#include "ray_set.h"

#include <algorithm>
#include <stdexcept>

#include "bulk_update.h"

namespace scenewatch::background {

void RaySet::reset(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi) {
  std::size_t cells = 1;
  for (int i = 0; i < 3; ++i) {
    const unsigned first = lo[i] > 0 ? lo[i] - 1u : 0u;
    const unsigned last = std::min<unsigned>(hi[i] + 1u, 0xffffu);
    lo_[i] = first >> kBlockLevels;
    dim_[i] = (last >> kBlockLevels) - lo_[i] + 1;
    cells *= dim_[i];
  }
  use_index_ = cells <= kMaxIndexedBlocks;
  blocks_.clear();
  coords_.clear();
  by_coords_.clear();
  if (use_index_) {
    index_.assign(cells, kNone);
  } else {
    std::vector<std::uint32_t>().swap(index_);
  }
}

std::uint32_t RaySet::find(unsigned bx, unsigned by, unsigned bz) const {
  if (use_index_) {
    const std::uint32_t* c = cell(bx, by, bz);
    return c ? *c : kNone;
  }
  const auto it = by_coords_.find(pack(bx, by, bz));
  return it == by_coords_.end() ? kNone : it->second;
}

std::uint32_t RaySet::find_or_add(unsigned bx, unsigned by, unsigned bz) {
  std::uint32_t* slot = nullptr;
  if (use_index_) {
    slot = const_cast<std::uint32_t*>(cell(bx, by, bz));
    if (slot == nullptr) return kNone;
  } else {
    slot = &by_coords_.try_emplace(pack(bx, by, bz), kNone).first.value();
  }
  if (*slot == kNone) {
    if (blocks_.size() >= (std::size_t{1} << kNumberBits)) throw std::length_error("RaySet: more than 2^25 blocks of rays in one frame");
    *slot = static_cast<std::uint32_t>(blocks_.size());
    blocks_.emplace_back();
    coords_.push_back(pack(bx, by, bz));
  }
  return *slot;
}

void RaySet::clear() {
  if (use_index_) {
    for (std::uint64_t c : coords_) {
      const std::uint32_t* cellp = cell(static_cast<unsigned>(c >> 32), static_cast<unsigned>((c >> 16) & 0xffff),
                                        static_cast<unsigned>(c & 0xffff));
      if (cellp != nullptr) *const_cast<std::uint32_t*>(cellp) = kNone;
    }
  }
  by_coords_.clear();
  blocks_.clear();
  coords_.clear();
}

void RaySet::merge(const RaySet& other) {
  for (std::size_t i = 0; i < other.blocks_.size(); ++i) {
    const std::uint64_t c = other.coords_[i];
    const std::uint32_t b = find_or_add(static_cast<unsigned>(c >> 32), static_cast<unsigned>((c >> 16) & 0xffff),
                                        static_cast<unsigned>(c & 0xffff));
    if (b == kNone) continue;  // other was reset with other bounds
    for (unsigned w = 0; w < kBlockVoxels / 64; ++w) {
      blocks_[b].free[w] |= other.blocks_[i].free[w];
      blocks_[b].end[w] |= other.blocks_[i].end[w];
    }
  }
}

void RaySet::morton_order(std::vector<std::uint64_t>& sorted, std::vector<std::uint64_t>& scratch) const {
  sorted.resize(blocks_.size());
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    const std::uint64_t c = coords_[i];
    const octomap::OcTreeKey block(static_cast<octomap::key_type>(c >> 32), static_cast<octomap::key_type>((c >> 16) & 0xffff),
                                   static_cast<octomap::key_type>(c & 0xffff));
    sorted[i] = (morton_encode(block) << kNumberBits) | i;
  }
  // Block coordinates have 16 - 3 bits per axis: the codes fit in 39 bits above the numbers.
  radix_sort(sorted, scratch, 3 * (16 - kBlockLevels) + kNumberBits);
}

std::size_t RaySet::count_freed() const {
  std::size_t n = 0;
  for (const Block& b : blocks_)
    for (unsigned w = 0; w < kBlockVoxels / 64; ++w) n += static_cast<std::size_t>(__builtin_popcountll(b.free[w] & ~b.end[w]));
  return n;
}

std::size_t RaySet::count_ends() const {
  std::size_t n = 0;
  for (const Block& b : blocks_)
    for (unsigned w = 0; w < kBlockVoxels / 64; ++w) n += static_cast<std::size_t>(__builtin_popcountll(b.end[w]));
  return n;
}

}  // namespace scenewatch::background
