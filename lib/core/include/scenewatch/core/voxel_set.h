#pragma once
/// A set of occupied voxels for "is there a point within about one voxel of p" questions: cheaper
/// than a k-d tree for the few thousand points of an object or a hand (the foreground's contacts
/// and masks, the object list's remembered surfaces).
#include <cmath>
#include <cstdint>
#include <unordered_set>

#include <Eigen/Core>

namespace scenewatch {

class VoxelSet {
 public:
  explicit VoxelSet(double voxel_m) : inv_(1.0 / voxel_m) {}
  /// Inserts the voxel of p; false when it was already there.
  bool insert(const Eigen::Vector3d& p) { return set_.insert(key(cell(p))).second; }
  /// True when p's voxel or one of its 26 neighbours holds a point (within 1 to 2.6 voxels).
  bool near(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = cell(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          if (set_.count(key(c + Eigen::Vector3i(dx, dy, dz)))) return true;
    return false;
  }
  bool empty() const { return set_.empty(); }
  /// True when p's own voxel holds a point (one lookup; use on a dilated() set for "near").
  bool contains(const Eigen::Vector3d& p) const { return set_.count(key(cell(p))) > 0; }
  /// The set grown by one voxel in every direction: contains() on it answers near() on this one
  /// with one lookup instead of 27 (worth it when many more points are asked than were inserted).
  VoxelSet dilated() const {
    VoxelSet out(1.0 / inv_);
    out.set_.reserve(set_.size() * 9);
    for (std::uint64_t k : set_) {
      const Eigen::Vector3i c = unkey(k);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) out.set_.insert(key(c + Eigen::Vector3i(dx, dy, dz)));
    }
    return out;
  }

 private:
  Eigen::Vector3i cell(const Eigen::Vector3d& p) const {
    return {static_cast<int>(std::floor(p.x() * inv_)), static_cast<int>(std::floor(p.y() * inv_)),
            static_cast<int>(std::floor(p.z() * inv_))};
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v + (1 << 20)) & 0x1FFFFF); };
    return u(c.x()) | (u(c.y()) << 21) | (u(c.z()) << 42);
  }
  static Eigen::Vector3i unkey(std::uint64_t k) {
    const auto v = [](std::uint64_t bits) { return static_cast<int>(bits & 0x1FFFFF) - (1 << 20); };
    return {v(k), v(k >> 21), v(k >> 42)};
  }
  double inv_;
  std::unordered_set<std::uint64_t> set_;
};

}  // namespace scenewatch
