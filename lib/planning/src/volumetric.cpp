// Rays walk the dense grid voxel by voxel (Amanatides & Woo, "A fast voxel traversal algorithm",
// Eurographics 1987) with an incremental index: no octree descent per voxel, which is where a
// plain OctoMap ray cast (computeRayKeys, then search() per key) spends its time. Voxels are
// counted once per view however many rays reach them (a per-voxel stamp, no clearing per call).
#include "scenewatch/planning/volumetric.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace scenewatch::planning {

using background::DenseGrid;
using background::Occupancy;

namespace {

constexpr std::uint8_t kUnknown = static_cast<std::uint8_t>(Occupancy::kUnknown);
constexpr std::uint8_t kOccupied = static_cast<std::uint8_t>(Occupancy::kOccupied);

double binary_entropy(double p) {
  if (p <= 0.0 || p >= 1.0) return 0.0;
  return -(p * std::log2(p) + (1.0 - p) * std::log2(1.0 - p));
}

}  // namespace

const char* to_string(Measure measure) {
  switch (measure) {
    case Measure::kUnobserved: return "unobserved";
    case Measure::kRearSide: return "rear_side";
    case Measure::kRearSideEntropy: return "rear_side_entropy";
    case Measure::kOcclusionAware: return "occlusion_aware";
    case Measure::kVisible: return "visible";
  }
  return "unobserved";
}

Result<Measure> parse_measure(const std::string& name) {
  for (Measure m : {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware, Measure::kVisible}) {
    if (name == to_string(m)) return m;
  }
  return invalid_argument("measure: unknown '" + name +
                          "' (unobserved, rear_side, rear_side_entropy, occlusion_aware, visible)");
}

Status validate(const VolumetricConfig& c) {
  if (c.rays_x < 1 || c.rays_x > 4096) return invalid_argument("planning.rays_x: must be in [1, 4096], got " + std::to_string(c.rays_x));
  if (c.rays_y < 1 || c.rays_y > 4096) return invalid_argument("planning.rays_y: must be in [1, 4096], got " + std::to_string(c.rays_y));
  if (!(c.max_range_m > 0.0 && c.max_range_m <= 100.0)) return invalid_argument("planning.max_range_m: must be in (0, 100] m");
  return {};
}

ViewScorer::ViewScorer(const DenseGrid& grid, const Aabb& target, VolumetricConfig config)
    : grid_(grid), config_(config), reached_(grid.size(), 0), rear_(grid.size(), 0) {
  const long n[3] = {grid.nx, grid.ny, grid.nz};
  for (int a = 0; a < 3; ++a) {
    // The voxels overlapping the box's inside: a face on a voxel boundary takes no extra layer.
    lo_[a] = std::max(0L, static_cast<long>(std::floor((target.min(a) - grid.origin(a)) / grid.resolution + 1e-9)));
    hi_[a] = std::min(n[a] - 1, static_cast<long>(std::ceil((target.max(a) - grid.origin(a)) / grid.resolution - 1e-9)) - 1);
  }
  if (!target.valid() || grid.size() == 0) {
    hi_[0] = hi_[1] = hi_[2] = -1;
    return;
  }
  for (long k = lo_[2]; k <= hi_[2]; ++k)
    for (long j = lo_[1]; j <= hi_[1]; ++j)
      for (long i = lo_[0]; i <= hi_[0]; ++i) {
        ++target_voxels_;
        if (grid.state[static_cast<std::size_t>((k * grid.ny + j) * grid.nx + i)] != kUnknown) ++target_known_;
      }
}

double ViewScorer::occupied_probability(long index) const {
  const auto it = std::lower_bound(grid_.occupied.begin(), grid_.occupied.end(), static_cast<std::size_t>(index),
                                   [](const DenseGrid::Surface& s, std::size_t i) { return s.index < i; });
  if (it == grid_.occupied.end() || it->index != static_cast<std::size_t>(index)) return 1.0;
  return it->probability / 255.0;
}

// Clip the ray to the grid: [t_enter, t_exit] in metres. Only target voxels count, and only the
// voxel just past the target can still matter (an occupied one ends a rear-side run): the ray is
// walked no further than the target box grown by one voxel, and not at all when it misses that
// box. The same counts, fewer steps.
bool ViewScorer::clip_ray(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_max, double& t_enter,
                          double& t_exit) const {
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  t_enter = 0.0, t_exit = t_max;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dg(a)) < 1e-12) {
      if (g0(a) < 0.0 || g0(a) >= n[a]) t_exit = -1.0;
      continue;
    }
    double t0 = -g0(a) / dg(a), t1 = (n[a] - g0(a)) / dg(a);
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
  }
  for (int a = 0; a < 3; ++a) {
    const double lo = lo_[a] - 1.0, hi = hi_[a] + 2.0;  // grid units, one voxel of margin
    if (std::abs(dg(a)) < 1e-12) {
      if (g0(a) < lo || g0(a) > hi) t_exit = -1.0;
      continue;
    }
    double t0 = (lo - g0(a)) / dg(a), t1 = (hi - g0(a)) / dg(a);
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_exit) t_exit = -1.0;
    t_exit = std::min(t_exit, t1);
  }
  return t_enter < t_exit;
}

void ViewScorer::walk_ray(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter, double t_exit,
                          std::uint32_t stamp, ViewGain& out, RaySums& sums) {
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  const long stride[3] = {1, grid_.nx, static_cast<long>(grid_.nx) * grid_.ny};
  long ijk[3], step[3];
  double t_next[3], t_delta[3];
  const Eigen::Vector3d start = g0 + (t_enter + 1e-9) * dg;
  for (int a = 0; a < 3; ++a) {
    ijk[a] = std::clamp(static_cast<long>(std::floor(start(a))), 0L, n[a] - 1);
    if (dg(a) > 0.0) {
      step[a] = 1;
      t_delta[a] = 1.0 / dg(a);
      t_next[a] = (ijk[a] + 1 - g0(a)) / dg(a);
    } else if (dg(a) < 0.0) {
      step[a] = -1;
      t_delta[a] = -1.0 / dg(a);
      t_next[a] = (ijk[a] - g0(a)) / dg(a);
    } else {
      step[a] = 0;
      t_delta[a] = t_next[a] = std::numeric_limits<double>::infinity();
    }
  }
  long index = ijk[0] * stride[0] + ijk[1] * stride[1] + ijk[2] * stride[2];
  double visibility = 1.0;
  long previous_unknown_target = -1;  // the voxel just walked, when unknown and in the target
  ray_unknown_.clear();
  for (;;) {
    ++out.steps;
    const bool in_target = ijk[0] >= lo_[0] && ijk[0] <= hi_[0] && ijk[1] >= lo_[1] && ijk[1] <= hi_[1] &&
                           ijk[2] >= lo_[2] && ijk[2] <= hi_[2];
    const std::uint8_t s = grid_.state[static_cast<std::size_t>(index)];
    const bool first = in_target && reached_[index] != stamp;
    if (first) {
      reached_[index] = stamp;
      ++out.target_reached;
    }
    if (s == kOccupied) {
      if (first) {
        const double h = binary_entropy(occupied_probability(index));
        sums.known_entropy += h;
        sums.occlusion_aware += visibility * h;
      }
      // Rear side (Isler et al.): the ray crossed unknown space and met a surface, so it
      // approached that surface from a side not yet seen.
      if (previous_unknown_target >= 0) {
        if (rear_[previous_unknown_target] != stamp) ++out.rear_side;
        for (long w : ray_unknown_) {
          if (rear_[w] == stamp || rear_[w] == stamp + 1) continue;
          rear_[w] = stamp + 1;
          sums.rear_entropy += 1.0;  // an unknown voxel: p = 0.5, one bit
        }
        rear_[previous_unknown_target] = stamp;
      }
      break;
    }
    if (s == kUnknown) {
      if (in_target) {
        ray_unknown_.push_back(index);
        if (first) {
          ++out.unknown_reached;
          sums.unknown_entropy += 1.0;
          sums.occlusion_aware += visibility;
        }
        previous_unknown_target = index;
      } else {
        previous_unknown_target = -1;
      }
      visibility *= 0.5;  // an unknown voxel is occupied with probability 0.5
    } else {
      previous_unknown_target = -1;
    }
    // Next voxel: cross the nearest boundary.
    const int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    if (t_next[a] > t_exit) break;
    ijk[a] += step[a];
    if (ijk[a] < 0 || ijk[a] >= n[a]) break;
    index += step[a] * stride[a];
    t_next[a] += t_delta[a];
  }
}

ViewGain ViewScorer::score(const Pose& T_world_camera, const Intrinsics& K, Measure measure) {
  ViewGain out;
  if (grid_.size() == 0 || !K.valid()) return out;
  // Two marks per call: the stamp counts a voxel as reached, the stamp + 1 (in rear_) as counted
  // by the rear-side measures. Restart the stamps before they wrap.
  if (stamp_ >= std::numeric_limits<std::uint32_t>::max() - 2) {
    std::fill(reached_.begin(), reached_.end(), 0);
    std::fill(rear_.begin(), rear_.end(), 0);
    stamp_ = 0;
  }
  const std::uint32_t stamp = ++stamp_;
  const double res = grid_.resolution;
  const Eigen::Vector3d g0 = (T_world_camera.translation() - grid_.origin) / res;  // grid units
  const Eigen::Matrix3d R = T_world_camera.linear();
  RaySums sums;

  for (int ry = 0; ry < config_.rays_y; ++ry) {
    const double v = (ry + 0.5) * K.height / config_.rays_y;
    for (int rx = 0; rx < config_.rays_x; ++rx) {
      const double u = (rx + 0.5) * K.width / config_.rays_x;
      const Eigen::Vector3d d_camera((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const double t_max = config_.max_range_m * d_camera.norm();  // the range is a depth (z)
      const Eigen::Vector3d dg = R * d_camera.normalized() / res;  // grid units per metre
      double t_enter = 0.0, t_exit = 0.0;
      if (!clip_ray(g0, dg, t_max, t_enter, t_exit)) continue;
      walk_ray(g0, dg, t_enter, t_exit, stamp, out, sums);
    }
  }
  // rear_ may hold stamp + 1 from this call: the next call's stamp skips past it.
  ++stamp_;
  out.entropy_bits = sums.unknown_entropy + sums.known_entropy;
  out.expected_coverage =
      target_voxels_ ? static_cast<double>(target_known_ + out.unknown_reached) / static_cast<double>(target_voxels_) : 0.0;
  switch (measure) {
    case Measure::kUnobserved: out.gain = static_cast<double>(out.unknown_reached); break;
    case Measure::kRearSide: out.gain = static_cast<double>(out.rear_side); break;
    case Measure::kRearSideEntropy: out.gain = sums.rear_entropy; break;
    case Measure::kOcclusionAware: out.gain = sums.occlusion_aware; break;
    case Measure::kVisible: out.gain = static_cast<double>(out.target_reached); break;
  }
  return out;
}

}  // namespace scenewatch::planning
