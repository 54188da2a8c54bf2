#pragma once
// The voxels the rays of one frame pass through, deduplicated in a dense bitmap over the frame's
// key bounding box (a segment's voxels never leave the box of its two end voxels), with a hash
// set as fallback when that box is too large for a bitmap.
// OcTreeKey.h uses uint16_t and size_t without including their headers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <tsl/robin_set.h>

#include "scenewatch/core/hash.h"

namespace scenewatch::background {

class RaySet {
 public:
  /// Prepares for keys inside [lo, hi] (inclusive) plus a margin of one voxel (float rounding can
  /// take a ray one voxel past its end box); clears the previous frame.
  void reset(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi);
  void insert_free(const octomap::OcTreeKey& k) { insert(k, free_bits_); }
  void insert_end(const octomap::OcTreeKey& k) { insert(k, end_bits_); }
  bool is_free(const octomap::OcTreeKey& k) const { return contains(k, free_bits_); }
  bool is_end(const octomap::OcTreeKey& k) const { return contains(k, end_bits_); }
  /// Passed through by a ray and not an endpoint (endpoints win, as in OctoMap's computeUpdate).
  bool freed(const octomap::OcTreeKey& k) const { return is_free(k) && !is_end(k); }
  /// Calls f(key, is_end) for every key that is an endpoint or freed.
  template <typename F>
  void for_each(F&& f) const;
  void clear();
  /// Adds every key of `other`, which was reset() with the same bounds.
  void merge(const RaySet& other);

 private:
  using Bits = std::vector<std::uint64_t>;
  static constexpr std::uint64_t kMaxBitmapVoxels = std::uint64_t{1} << 30;  // 128 MiB per bitmap

  bool in_box(const octomap::OcTreeKey& k) const {
    return k[0] >= lo_[0] && k[1] >= lo_[1] && k[2] >= lo_[2] && k[0] < lo_[0] + dim_[0] && k[1] < lo_[1] + dim_[1] &&
           k[2] < lo_[2] + dim_[2];
  }
  std::uint64_t index(const octomap::OcTreeKey& k) const {
    return (static_cast<std::uint64_t>(k[0] - lo_[0]) * dim_[1] + (k[1] - lo_[1])) * dim_[2] + (k[2] - lo_[2]);
  }
  static std::uint64_t pack(const octomap::OcTreeKey& k) {
    return (static_cast<std::uint64_t>(k[0]) << 32) | (static_cast<std::uint64_t>(k[1]) << 16) | k[2];
  }
  void insert(const octomap::OcTreeKey& k, Bits& bits) {
    if (use_bitmap_) {
      if (!in_box(k)) return;  // cannot happen with the padded box; never write outside the bitmap
      const std::uint64_t i = index(k);
      bits[i >> 6] |= std::uint64_t{1} << (i & 63);
    } else {
      (&bits == &free_bits_ ? free_set_ : end_set_).insert(pack(k));
    }
  }
  bool contains(const octomap::OcTreeKey& k, const Bits& bits) const {
    if (use_bitmap_) {
      if (!in_box(k)) return false;
      const std::uint64_t i = index(k);
      return (bits[i >> 6] >> (i & 63)) & 1;
    }
    return (&bits == &free_bits_ ? free_set_ : end_set_).count(pack(k)) > 0;
  }

  bool use_bitmap_ = true;
  octomap::OcTreeKey lo_{0, 0, 0};
  std::uint32_t dim_[3] = {0, 0, 0};
  Bits free_bits_, end_bits_;
  tsl::robin_set<std::uint64_t, MixHash64> free_set_, end_set_;
};

template <typename F>
void RaySet::for_each(F&& f) const {
  if (use_bitmap_) {
    const std::uint64_t dz = dim_[2], dy = dim_[1];
    for (std::size_t w = 0; w < free_bits_.size(); ++w) {
      std::uint64_t any = free_bits_[w] | end_bits_[w];
      if (!any) continue;
      // The word's first index split into x, y, z once (divisions); the bits after it step along
      // z, wrapping into y and x.
      const std::uint64_t first = static_cast<std::uint64_t>(w) << 6;
      std::uint64_t z = first % dz, y = (first / dz) % dy, x = first / (dz * dy), at = first;
      while (any) {
        const int b = __builtin_ctzll(any);
        any &= any - 1;
        const std::uint64_t i = first | static_cast<std::uint64_t>(b);
        z += i - at;
        at = i;
        while (z >= dz) {
          z -= dz;
          if (++y == dy) y = 0, ++x;
        }
        const octomap::OcTreeKey k(static_cast<octomap::key_type>(lo_[0] + x), static_cast<octomap::key_type>(lo_[1] + y),
                                   static_cast<octomap::key_type>(lo_[2] + z));
        f(k, static_cast<bool>((end_bits_[w] >> b) & 1));
      }
    }
    return;
  }
  for (std::uint64_t p : end_set_) f(octomap::OcTreeKey(p >> 32, (p >> 16) & 0xffff, p & 0xffff), true);
  for (std::uint64_t p : free_set_) {
    if (end_set_.count(p) == 0) f(octomap::OcTreeKey(p >> 32, (p >> 16) & 0xffff, p & 0xffff), false);
  }
}

}  // namespace scenewatch::background
