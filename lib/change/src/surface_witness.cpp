#include "scenewatch/change/surface_witness.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "voxel_axis.h"

namespace scenewatch::change {

SurfaceWitness::SurfaceWitness(double voxel_m, std::size_t max_voxels) : per_m_(1.0 / voxel_m), max_voxels_(max_voxels) {}

SurfaceWitness::Where SurfaceWitness::where(const Eigen::Vector3d& p) const {
  const std::uint64_t x = voxel_axis(p.x(), per_m_), y = voxel_axis(p.y(), per_m_), z = voxel_axis(p.z(), per_m_);
  constexpr std::uint64_t low = (1u << kBlockBits) - 1;
  Where w;
  constexpr unsigned kBits = 21 - kBlockBits;  // per axis of a block key
  w.block = ((x >> kBlockBits) << (2 * kBits)) | ((y >> kBlockBits) << kBits) | (z >> kBlockBits);
  w.voxel = static_cast<unsigned>((x & low) | ((y & low) << kBlockBits) | ((z & low) << (2 * kBlockBits)));
  return w;
}

SurfaceWitness::Entry* SurfaceWitness::find(const Where& w) {
  const auto it = blocks_by_key_.find(w.block);
  return it == blocks_by_key_.end() ? nullptr : &blocks_[it->second].voxels[w.voxel];
}

std::uint32_t SurfaceWitness::block_of(std::uint64_t block_key) {
  const auto it = blocks_by_key_.find(block_key);
  if (it != blocks_by_key_.end()) return it->second;
  std::uint32_t b;
  if (!free_blocks_.empty()) {
    b = free_blocks_.back();
    free_blocks_.pop_back();
    block_keys_[b] = block_key;
  } else {
    b = static_cast<std::uint32_t>(blocks_.size());
    blocks_.emplace_back();
    block_keys_.push_back(block_key);
  }
  blocks_by_key_.emplace(block_key, b);
  return b;
}

void SurfaceWitness::clear(std::uint32_t b, unsigned voxel) {
  Block& block = blocks_[b];
  Entry& e = block.voxels[voxel];
  if (e.cameras == 0) return;
  e = Entry{};
  --live_;
  if (--block.live > 0) return;
  blocks_by_key_.erase(block_keys_[b]);
  free_blocks_.push_back(b);
}

void SurfaceWitness::reset() {
  blocks_by_key_.clear();
  blocks_.clear();
  block_keys_.clear();
  free_blocks_.clear();
  live_ = 0;
}

void SurfaceWitness::witness(const Cloud& cloud, const Pose& T, std::uint32_t camera, int stride) {
  ++frame_;
  const std::uint64_t bit = std::uint64_t{1} << (camera % 64);
  const Eigen::Isometry3f Tf = T.cast<float>();
  // Neighbouring pixels mostly fall in one voxel (a 2 cm voxel spans 5 pixels at 2 m), in this
  // row and in the rows above: marking it again, at no smaller depth, changes nothing. A small
  // table of the voxels marked in this frame (direct-mapped by key, with the depth marked) spares
  // most of the lookups.
  if (recent_.empty()) recent_.resize(kRecent);
  // Two passes: the voxels to mark first, then the marks, each entry fetched a few marks ahead.
  // Most entries a frame touches are not in the cache; fetched one by one, the witness waited for
  // memory on half its time (kitchen). The marks commute, so the order changes nothing.
  marks_.clear();
  std::uint64_t last_block = 0;
  std::uint32_t b = 0;
  bool have_block = false;
  auto add = [&](const PointT& p) {
    if (!is_valid(p)) return;
    const Where w = where((Tf * p.getVector3fMap()).cast<double>());
    const std::uint64_t k = (w.block << (3 * kBlockBits)) | w.voxel;  // unique: 57 + 6 bits
    Recent& r = recent_[(k ^ (k >> 19) ^ (k >> 40)) & (kRecent - 1)];
    if (r.frame == frame_ && r.key == k && p.z >= r.depth_m) return;
    r = {k, frame_, p.z};
    if (!have_block || w.block != last_block) {
      b = block_of(w.block);
      last_block = w.block;
      have_block = true;
    }
    marks_.push_back({b, w.voxel, p.z});
  };
  if (cloud.height > 1 && stride > 1) {
    for (std::uint32_t v = 0; v < cloud.height; v += static_cast<std::uint32_t>(stride))
      for (std::uint32_t u = 0; u < cloud.width; u += static_cast<std::uint32_t>(stride)) add(cloud.points[v * cloud.width + u]);
  } else {
    for (const auto& p : cloud.points) add(p);
  }
  constexpr std::size_t kAhead = 8;
  for (std::size_t i = 0; i < marks_.size(); ++i) {
    if (i + kAhead < marks_.size()) {
      const Mark& next = marks_[i + kAhead];
      __builtin_prefetch(&blocks_[next.block].voxels[next.voxel], 1);
    }
    const Mark& m = marks_[i];
    Block& block = blocks_[m.block];
    Entry& e = block.voxels[m.voxel];
    if (e.cameras == 0) ++live_, ++block.live;
    e.cameras |= bit;
    e.last_frame = static_cast<std::uint32_t>(frame_);
    if (e.nearest_depth_m == 0.0f || m.depth_m < e.nearest_depth_m) e.nearest_depth_m = m.depth_m;
  }
  if (live_ > max_voxels_) prune();
}

SurfaceWitness::Seen SurfaceWitness::seen(const Eigen::Vector3d& p, std::uint32_t camera, double* nearest_depth_m) const {
  const Entry* e = find(where(p));
  const bool none = e == nullptr || e->cameras == 0;
  if (nearest_depth_m != nullptr) *nearest_depth_m = none ? 0.0 : e->nearest_depth_m;
  if (none) return Seen::kByNone;
  return (e->cameras & (std::uint64_t{1} << (camera % 64))) != 0 ? Seen::kBySelf : Seen::kByOthersOnly;
}

void SurfaceWitness::forget(const std::vector<Eigen::Vector3d>& points) {
  for (const auto& p : points) {
    const Where w = where(p);
    const auto it = blocks_by_key_.find(w.block);
    if (it != blocks_by_key_.end()) clear(it->second, w.voxel);
  }
}

// Keeps the three quarters of the limit seen most recently. Ages are counted modulo 2^32 frames
// (a frame number is kept in 32 bits), so they stay right when the count wraps.
void SurfaceWitness::prune() {
  const auto now = static_cast<std::uint32_t>(frame_);
  std::vector<std::uint32_t> ages;
  ages.reserve(live_);
  for (const auto& [key, b] : blocks_by_key_)
    for (const Entry& e : blocks_[b].voxels)
      if (e.cameras != 0) ages.push_back(now - e.last_frame);
  const std::size_t keep = max_voxels_ * 3 / 4;
  std::nth_element(ages.begin(), ages.begin() + static_cast<long>(keep) - 1, ages.end());
  const std::uint32_t oldest_kept = ages[keep - 1];
  std::vector<std::uint32_t> live_blocks;
  live_blocks.reserve(blocks_by_key_.size());
  for (const auto& [key, b] : blocks_by_key_) live_blocks.push_back(b);
  for (std::uint32_t b : live_blocks)
    for (unsigned v = 0; v < kBlockVoxels; ++v) {
      const Entry& e = blocks_[b].voxels[v];
      if (e.cameras != 0 && static_cast<std::uint32_t>(now - e.last_frame) > oldest_kept) clear(b, v);
    }
}

}  // namespace scenewatch::change
