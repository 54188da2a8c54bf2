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
    slot = cell(bx, by, bz);
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
      if (std::uint32_t* slot = cell(unpack_key(c))) *slot = kNone;
    }
  }
  by_coords_.clear();
  blocks_.clear();
  coords_.clear();
}

void RaySet::merge(const RaySet& other) {
  for (std::size_t i = 0; i < other.blocks_.size(); ++i) {
    const octomap::OcTreeKey block = unpack_key(other.coords_[i]);
    const std::uint32_t b = find_or_add(block[0], block[1], block[2]);
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
    sorted[i] = (morton_encode(unpack_key(coords_[i])) << kNumberBits) | i;
  }
  // Block coordinates have 16 - 3 bits per axis: the codes fit in 39 bits above the numbers.
  radix_sort(sorted, scratch, 3 * (16 - kBlockLevels) + kNumberBits);
}

namespace {
// The bits of every block's words that `bits(free, end)` keeps.
template <typename Bits>
std::size_t count_bits(const std::vector<RaySet::Block>& blocks, Bits bits) {
  std::size_t n = 0;
  for (const RaySet::Block& b : blocks)
    for (unsigned w = 0; w < RaySet::kBlockVoxels / 64; ++w) n += static_cast<std::size_t>(__builtin_popcountll(bits(b.free[w], b.end[w])));
  return n;
}
}  // namespace

std::size_t RaySet::count_freed() const {
  return count_bits(blocks_, [](std::uint64_t free, std::uint64_t end) { return free & ~end; });
}

std::size_t RaySet::count_ends() const {
  return count_bits(blocks_, [](std::uint64_t, std::uint64_t end) { return end; });
}

}  // namespace scenewatch::background
