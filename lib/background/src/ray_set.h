#pragma once
// The voxels the rays of one frame pass through and end in, kept in blocks of 8x8x8 voxels.
//
// A block is the cube of one tree node three levels above the leaves, aligned as OctoMap's keys
// are, and holds its voxels' bits in Morton order (bit = the three child indices of the levels
// below it): one 64-byte line of "passed through" bits and one of "ended here" bits. A ray's
// consecutive steps mostly stay in one line, and the tree update (bulk_update.h) reads a node's
// cube as a contiguous run of bits: no per-voxel key list and no sort of millions of keys.
// Blocks are created on first touch; a dense index over the frame's box finds them, or a hash
// map when that box holds too many blocks for an index.
// OcTreeKey.h uses uint16_t and size_t without including their headers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <tsl/robin_map.h>

#include "packed_key.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::background {

class RaySet {
 public:
  static constexpr unsigned kBlockLevels = 3;  // a block is 2^3 voxels per axis
  static constexpr unsigned kBlockVoxels = 1u << (3 * kBlockLevels);

  struct alignas(64) Block {
    std::uint64_t free[kBlockVoxels / 64];  // passed through by a ray
    std::uint64_t end[kBlockVoxels / 64];   // a ray's end voxel
  };

  /// Prepares for keys inside [lo, hi] (inclusive) plus a margin of one voxel (float rounding can
  /// take a ray one voxel past its end box); clears the previous frame.
  void reset(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi);
  void insert_free(const octomap::OcTreeKey& k) { set(k, &Block::free); }
  void insert_end(const octomap::OcTreeKey& k) { set(k, &Block::end); }
  bool is_free(const octomap::OcTreeKey& k) const { return test(k, &Block::free); }
  bool is_end(const octomap::OcTreeKey& k) const { return test(k, &Block::end); }
  /// Passed through by a ray and not an endpoint (endpoints win, as in OctoMap's computeUpdate).
  bool freed(const octomap::OcTreeKey& k) const { return is_free(k) && !is_end(k); }
  void clear();
  /// Adds every key of `other`, which was reset() with the same bounds.
  void merge(const RaySet& other);

  const std::vector<Block>& blocks() const { return blocks_; }
  /// The blocks in the order of a depth-first tree walk, each as (code << kNumberBits) | number:
  /// the code is the Morton code of the block's coordinates (its voxels' keys shifted right by
  /// three), so its voxels' codes are (code << 9) | bit; the number indexes blocks().
  void morton_order(std::vector<std::uint64_t>& sorted, std::vector<std::uint64_t>& scratch) const;
  static constexpr unsigned kNumberBits = 25;
  /// Voxels freed (passed through and not an end) and voxels ended in.
  std::size_t count_freed() const;
  std::size_t count_ends() const;

  /// Sets voxels' "passed through" bits along one ray, keeping the current block at hand: a
  /// ray's steps mostly stay in one block. While a writer is in use, nothing else may add to
  /// its set (a new block can move the others).
  class FreeWriter {
   public:
    explicit FreeWriter(RaySet& set) : set_(set) {}
    /// Sets k's bit; true if it was set already.
    bool test_and_set(const octomap::OcTreeKey& k) {
      const unsigned bx = k[0] >> kBlockLevels, by = k[1] >> kBlockLevels, bz = k[2] >> kBlockLevels;
      if (block_ == nullptr || bx != bx_ || by != by_ || bz != bz_) {
        const std::uint32_t b = set_.find_or_add(bx, by, bz);
        if (b == kNone) return true;  // outside the padded box: cannot happen; write nothing
        block_ = &set_.blocks_[b];
        bx_ = bx, by_ = by, bz_ = bz;
      }
      const unsigned bit = bit_of(k);
      std::uint64_t& word = block_->free[bit >> 6];
      const std::uint64_t mask = std::uint64_t{1} << (bit & 63);
      const bool was_set = (word & mask) != 0;
      word |= mask;
      return was_set;
    }

   private:
    RaySet& set_;
    Block* block_ = nullptr;
    unsigned bx_ = 0, by_ = 0, bz_ = 0;
  };

  /// The bit of a key inside its block: its low three bits per axis, interleaved (x lowest).
  static unsigned bit_of(const octomap::OcTreeKey& k) {
    return kSpread3[k[0] & 7] | (kSpread3[k[1] & 7] << 1) | (kSpread3[k[2] & 7] << 2);
  }

 private:
  static constexpr unsigned kSpread3[8] = {0, 1, 8, 9, 64, 65, 72, 73};
  static constexpr std::size_t kMaxIndexedBlocks = std::size_t{1} << 22;  // a 16 MiB index
  static constexpr std::uint32_t kNone = 0xffffffffu;
  using Words = std::uint64_t (Block::*)[kBlockVoxels / 64];

  /// A block's coordinates (its voxels' keys shifted right by three) as one packed key.
  static std::uint64_t pack(unsigned bx, unsigned by, unsigned bz) {
    return pack_key(octomap::OcTreeKey(static_cast<octomap::key_type>(bx), static_cast<octomap::key_type>(by),
                                       static_cast<octomap::key_type>(bz)));
  }
  /// The index cell of block (bx, by, bz), or nullptr outside the indexed box.
  const std::uint32_t* cell(unsigned bx, unsigned by, unsigned bz) const {
    const unsigned x = bx - lo_[0], y = by - lo_[1], z = bz - lo_[2];  // wraps below lo_
    if (x >= dim_[0] || y >= dim_[1] || z >= dim_[2]) return nullptr;
    return &index_[(static_cast<std::size_t>(x) * dim_[1] + y) * dim_[2] + z];
  }
  std::uint32_t* cell(unsigned bx, unsigned by, unsigned bz) {
    return const_cast<std::uint32_t*>(static_cast<const RaySet&>(*this).cell(bx, by, bz));
  }
  std::uint32_t* cell(const octomap::OcTreeKey& block) { return cell(block[0], block[1], block[2]); }
  std::uint32_t find(unsigned bx, unsigned by, unsigned bz) const;
  std::uint32_t find_or_add(unsigned bx, unsigned by, unsigned bz);
  void set(const octomap::OcTreeKey& k, Words words) {
    const std::uint32_t b = find_or_add(k[0] >> kBlockLevels, k[1] >> kBlockLevels, k[2] >> kBlockLevels);
    if (b == kNone) return;  // outside the padded box: cannot happen; never write outside the index
    const unsigned bit = bit_of(k);
    (blocks_[b].*words)[bit >> 6] |= std::uint64_t{1} << (bit & 63);
  }
  bool test(const octomap::OcTreeKey& k, Words words) const {
    const std::uint32_t b = find(k[0] >> kBlockLevels, k[1] >> kBlockLevels, k[2] >> kBlockLevels);
    if (b == kNone) return false;
    const unsigned bit = bit_of(k);
    return ((blocks_[b].*words)[bit >> 6] >> (bit & 63)) & 1;
  }

  bool use_index_ = true;
  unsigned lo_[3] = {0, 0, 0};   // block coordinates of the indexed box's corner
  unsigned dim_[3] = {0, 0, 0};  // and its size in blocks
  std::vector<std::uint32_t> index_;  // block number per cell of the box, kNone where untouched
  tsl::robin_map<std::uint64_t, std::uint32_t, MixHash64> by_coords_;  // when the box is too large
  std::vector<Block> blocks_;
  std::vector<std::uint64_t> coords_;  // pack(bx, by, bz) of each block
};

}  // namespace scenewatch::background
