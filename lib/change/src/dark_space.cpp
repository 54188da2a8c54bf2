// Space rays without a return crossed on their way to known surfaces (dark_space.h).
#include "scenewatch/change/dark_space.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "scenewatch/change/mismatch.h"
#include "voxel_axis.h"

namespace scenewatch::change {
namespace {

// Two rays look at a voxel from distinct views when their directions differ by this much. A
// specular highlight or a dark, glossy patch drops out of a structured-light image over a few
// degrees of viewing angle; the appearance memory takes a new keyframe at 5 degrees of turn.
constexpr double kDistinctViewDeg = 10.0;
// Holes are sampled on every kSampleStep-th pixel and row per 640 pixels of image width: at 1.5 m
// a VGA Kinect's 8 pixels span 2.3 cm, about a map voxel, so no voxel-sized gap is skipped.
constexpr double kSampleStep = 8.0;
// Half the diagonal of a unit cube (as in mismatch.cpp).
constexpr double kHalfDiagonal = 0.8660254;
constexpr unsigned kBlockBits = 3;  // blocks of 8 x 8 x 8 voxels (16 cm at 2 cm)
constexpr std::uint64_t kBlockAxisMask = kVoxelAxisMask >> kBlockBits;

// A voxel key's three axis indices (x, y, z).
std::array<std::uint64_t, 3> axes(std::uint64_t key) { return {key >> 42, (key >> 21) & kVoxelAxisMask, key & kVoxelAxisMask}; }
// The key of the block holding the voxel at these axis indices.
std::uint64_t block_key(std::uint64_t bx, std::uint64_t by, std::uint64_t bz) {
  return ((bx & kBlockAxisMask) << 36) | ((by & kBlockAxisMask) << 18) | (bz & kBlockAxisMask);
}

}  // namespace

DarkSpace::DarkSpace(double voxel_m, std::size_t max_voxels) : per_m_(1.0 / voxel_m), max_voxels_(max_voxels) {}

std::uint64_t DarkSpace::key(const Eigen::Vector3d& p) const {
  return (voxel_axis(p.x(), per_m_) << 42) | (voxel_axis(p.y(), per_m_) << 21) | voxel_axis(p.z(), per_m_);
}

void DarkSpace::record(const background::DenseGrid& grid, const DepthView& depth, const Pose& T, const Config& config,
                       std::uint32_t camera) {
  ++frame_;
  const Intrinsics& K = depth.K;
  if (grid.size() == 0 || !K.valid()) return;
  const double res = grid.resolution;
  if (std::abs(res * per_m_ - 1.0) > 1e-6) {  // the map was replaced by one of another resolution
    voxels_.clear();
    blocks_.clear();
    per_m_ = 1.0 / res;
  }
  const int step = std::max(1, static_cast<int>(std::lround(kSampleStep * K.width / 640.0)));
  const int border = std::max(config.sensor.border_px, 0);
  // The depths this camera has measured at all: a hole in front of a surface nearer or farther
  // than any of them is the sensor's range, not something in front (a Kinect v1 in its default
  // mode returns nothing under 0.8 m, whatever its profile's working range says).
  Range& measured = ranges_[camera];
  if (depth.min_z > 0) {  // NaN when the frame has no depth at all
    measured.min_m = std::min(measured.min_m, static_cast<double>(depth.min_z));
    measured.max_m = std::max(measured.max_m, static_cast<double>(depth.max_z));
  }
  if (!(measured.min_m < measured.max_m)) return;
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d origin = T.translation();
  const std::uint64_t bit = std::uint64_t{1} << (camera % 64);
  const double cos_distinct = std::cos(kDistinctViewDeg * M_PI / 180.0);
  std::vector<std::pair<long, double>> crossed;  // unknown voxels along one ray, their centres' distance along it
  for (int v = border; v < K.height - border; v += step) {
    for (int u = border; u < K.width - border; u += step) {
      if (depth.at(u, v) > 0) continue;  // a return: the map takes it
      const Eigen::Vector3d ray_camera((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const double per_z = ray_camera.norm();  // distance along the ray per metre of camera z
      const Eigen::Vector3d d = R * (ray_camera / per_z);
      // Walk the ray through the map before this frame until its first surface.
      crossed.clear();
      double surface_t = -1.0;
      long last = -2;
      const double t_end = config.max_range_m * per_z;
      for (double t = config.sensor.min_range_m * per_z; t <= t_end; t += 0.5 * res) {
        const long idx = grid.index_of(origin + t * d);
        if (idx == last) continue;
        last = idx;
        if (idx < 0) break;  // out of the frame's box: no surface of it ahead
        const auto state = grid.at(idx);
        if (state == background::Occupancy::kOccupied) {
          surface_t = t;
          break;
        }
        if (state == background::Occupancy::kUnknown) crossed.emplace_back(idx, (grid.center(idx) - origin).dot(d));
      }
      if (surface_t < 0 || crossed.empty()) continue;
      // The surface itself lies anywhere within its tolerance of the voxel that holds it: a dark
      // patch of that surface (no return) is no space in front of it.
      const double z_surface = surface_t / per_z;
      const double noise = config.sigma_factor * config.sensor.sigma_z(z_surface);
      if (z_surface < measured.min_m + noise || z_surface > measured.max_m - noise) continue;
      const double front = surface_t - (map_tolerance_m(config, z_surface) + 2 * kHalfDiagonal * res) * per_z;
      for (const auto& [idx, t] : crossed) {
        if (t > front) continue;
        const std::uint64_t k = key(grid.center(idx));
        auto [it, added] = voxels_.try_emplace(k);
        if (added) blocks_[block_of(k)].push_back(k);
        Entry& e = it.value();
        e.cameras |= bit;
        if (e.seen_through) e.mixed = true;
        if (e.frames > 0 && e.last_frame == frame_) continue;
        e.last_frame = frame_;
        if (e.frames == 0) {
          for (int k = 0; k < 3; ++k) e.first_dir[k] = static_cast<float>(d(k));
        } else if (!e.two_views && Eigen::Vector3f(e.first_dir).cast<double>().dot(d) < cos_distinct) {
          e.two_views = true;
        }
        if (e.frames < 0xffff) ++e.frames;
      }
    }
  }
  if (voxels_.size() > max_voxels_) prune();
}

void DarkSpace::prune() {
  // Forget what no ray crossed for the longest: the older half by last_frame.
  std::vector<std::uint32_t> ages;
  ages.reserve(voxels_.size());
  for (const auto& [k, e] : voxels_) ages.push_back(frame_ - e.last_frame);
  auto mid = ages.begin() + static_cast<long>(ages.size() / 2);
  std::nth_element(ages.begin(), mid, ages.end());
  const std::uint32_t cut = *mid;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if (frame_ - it->second.last_frame >= cut && cut > 0) it = voxels_.erase(it);
    else ++it;
  }
  if (voxels_.size() > max_voxels_) voxels_.clear();  // every entry as old as the rest
  blocks_.clear();
  for (const auto& [k, e] : voxels_) blocks_[block_of(k)].push_back(k);
}

std::uint64_t DarkSpace::block_of(std::uint64_t k) {
  const auto a = axes(k);
  return block_key(a[0] >> kBlockBits, a[1] >> kBlockBits, a[2] >> kBlockBits);
}

void DarkSpace::erase(std::uint64_t k) {
  if (voxels_.erase(k) == 0) return;
  auto block = blocks_.find(block_of(k));
  if (block == blocks_.end()) return;
  auto& keys = block.value();
  const auto at = std::find(keys.begin(), keys.end(), k);
  if (at != keys.end()) {
    *at = keys.back();
    keys.pop_back();
  }
  if (keys.empty()) blocks_.erase(block);
}

std::vector<DarkSpace::Voxel> DarkSpace::in_grid(const background::DenseGrid& grid, std::uint32_t camera, int min_frames) const {
  std::vector<Voxel> out;
  if (grid.size() == 0) return out;
  const std::uint64_t bit = std::uint64_t{1} << (camera % 64);
  // Only the blocks the grid overlaps: a daemon that has run for hours holds many more.
  const Eigen::Vector3d lo = grid.origin.array() + 0.5 * grid.resolution;
  const Eigen::Vector3d hi = grid.origin + grid.resolution * Eigen::Vector3d(grid.nx - 0.5, grid.ny - 0.5, grid.nz - 0.5);
  const auto a0 = axes(key(lo)), a1 = axes(key(hi));
  for (std::uint64_t x = a0[0] >> kBlockBits; x <= a1[0] >> kBlockBits; ++x)
    for (std::uint64_t y = a0[1] >> kBlockBits; y <= a1[1] >> kBlockBits; ++y)
      for (std::uint64_t z = a0[2] >> kBlockBits; z <= a1[2] >> kBlockBits; ++z) {
        const auto block = blocks_.find(block_key(x, y, z));
        if (block == blocks_.end()) continue;
        for (const std::uint64_t k : block->second) {
          const Entry& e = voxels_.find(k)->second;
          if (e.mixed) continue;
          const auto a = axes(k);
          const Eigen::Vector3d c(voxel_axis_center(a[0], per_m_), voxel_axis_center(a[1], per_m_), voxel_axis_center(a[2], per_m_));
          const long idx = grid.index_of(c);
          if (idx < 0 || grid.at(idx) == background::Occupancy::kOccupied) continue;
          out.push_back({k, grid.center(idx), e.two_views && e.frames >= min_frames && (e.cameras & bit) != 0});
        }
      }
  return out;
}

void DarkSpace::seen_through(std::uint64_t k) {
  auto it = voxels_.find(k);
  if (it != voxels_.end()) it.value().seen_through = true;
}

void DarkSpace::forget(const std::vector<Eigen::Vector3d>& points_world) {
  for (const auto& p : points_world) erase(key(p));
}

std::size_t DarkSpace::dark_voxels(int min_frames) const {
  return static_cast<std::size_t>(std::count_if(voxels_.begin(), voxels_.end(), [&](const auto& kv) {
    return !kv.second.mixed && kv.second.two_views && kv.second.frames >= min_frames;
  }));
}

void DarkSpace::reset() {
  voxels_.clear();
  blocks_.clear();
  ranges_.clear();
  frame_ = 0;
}

}  // namespace scenewatch::change
