#pragma once
// A world coordinate as a voxel index on one axis, for the packed voxel keys of the change
// detector's per-voxel memories (surface_witness.cpp, dark_space.cpp): 21 bits per axis around
// the origin, +-20 km at 2 cm.
#include <cmath>
#include <cstdint>

namespace scenewatch::change {

inline constexpr std::uint64_t kVoxelAxisMask = 0x1fffff;
inline constexpr std::int64_t kVoxelAxisOffset = std::int64_t{1} << 20;

// floor() written out: without SSE4.1 in an x86-64 baseline build std::floor is a libm call,
// three per point (as in background/frame_trace.cpp).
inline std::uint64_t voxel_axis(double x, double per_m) {
  const double a = x * per_m;
  std::int64_t f;
  if (a > -4e18 && a < 4e18) {
    f = static_cast<std::int64_t>(a);  // towards zero
    if (a < static_cast<double>(f)) --f;
  } else {
    f = static_cast<std::int64_t>(std::floor(a));
  }
  return static_cast<std::uint64_t>(f + kVoxelAxisOffset) & kVoxelAxisMask;
}

// The centre of voxel index `a` on its axis, metres.
inline double voxel_axis_center(std::uint64_t a, double per_m) {
  return (static_cast<double>(static_cast<std::int64_t>(a) - kVoxelAxisOffset) + 0.5) / per_m;
}

}  // namespace scenewatch::change
