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
constexpr std::uint8_t kFree = static_cast<std::uint8_t>(Occupancy::kFree);
constexpr std::uint8_t kOccupied = static_cast<std::uint8_t>(Occupancy::kOccupied);

double binary_entropy(double p) {
  if (p <= 0.0 || p >= 1.0) return 0.0;
  return -(p * std::log2(p) + (1.0 - p) * std::log2(1.0 - p));
}

// The probability a grid's list (sorted by index) holds for voxel `index`, `absent` when it is not listed.
double listed_probability(const std::vector<DenseGrid::Surface>& listed, long index, double absent) {
  const auto it = std::lower_bound(listed.begin(), listed.end(), static_cast<std::size_t>(index),
                                   [](const DenseGrid::Surface& s, std::size_t i) { return s.index < i; });
  if (it == listed.end() || it->index != static_cast<std::size_t>(index)) return absent;
  return it->probability / 255.0;
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

ViewScorer::ViewScorer(const DenseGrid& grid, const Aabb& target, VolumetricConfig config,
                       const std::vector<Eigen::Vector3d>& surface_world)
    : grid_(grid), config_(config) {
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
  for (int a = 0; a < 3; ++a) span_[a] = std::max(0L, hi_[a] - lo_[a] + 1);
  reached_.assign(static_cast<std::size_t>(span_[0] * span_[1] * span_[2]), 0);
  rear_.assign(reached_.size(), 0);
  // The uniform blocks: the states present in each (a bit per state), then the target's blocks
  // mixed whatever their states.
  constexpr long kSide = 1L << kBlockShift;
  for (int a = 0; a < 3; ++a) blocks_[a] = (n[a] + kSide - 1) >> kBlockShift;
  block_.assign(static_cast<std::size_t>(blocks_[0] * blocks_[1] * blocks_[2]), 0);
  const std::uint8_t* voxel = grid.state.data();
  for (long k = 0; k < n[2]; ++k)
    for (long j = 0; j < n[1]; ++j) {
      std::uint8_t* const row = &block_[static_cast<std::size_t>(((k >> kBlockShift) * blocks_[1] + (j >> kBlockShift)) * blocks_[0])];
      for (long i = 0; i < n[0]; ++i, ++voxel) row[i >> kBlockShift] |= static_cast<std::uint8_t>(1u << *voxel);
    }
  for (std::uint8_t& b : block_) {
    b = b == 1u << kFree ? kFreeBlock : b == 1u << kUnknown ? kUnknownBlock : kMixedBlock;
  }
  for (long k = lo_[2] >> kBlockShift; k <= hi_[2] >> kBlockShift; ++k)
    for (long j = lo_[1] >> kBlockShift; j <= hi_[1] >> kBlockShift; ++j)
      for (long i = lo_[0] >> kBlockShift; i <= hi_[0] >> kBlockShift; ++i)
        block_[static_cast<std::size_t>((k * blocks_[1] + j) * blocks_[0] + i)] = kMixedBlock;
  if (!surface_world.empty()) {
    surface_.assign(reached_.size(), 0);
    for (const Eigen::Vector3d& p : surface_world) {
      const Eigen::Vector3d g = (p - grid.origin) / grid.resolution;
      if (!g.allFinite()) continue;
      long ijk[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        ijk[a] = static_cast<long>(std::floor(g(a)));
        inside = inside && ijk[a] >= lo_[a] && ijk[a] <= hi_[a];
      }
      if (inside) surface_[static_cast<std::size_t>(mark_of(ijk))] = 1;
    }
  }
  for (long k = lo_[2]; k <= hi_[2]; ++k)
    for (long j = lo_[1]; j <= hi_[1]; ++j)
      for (long i = lo_[0]; i <= hi_[0]; ++i) {
        const long ijk[3] = {i, j, k};
        if (!surface_.empty() && !surface_[static_cast<std::size_t>(mark_of(ijk))]) continue;
        ++target_voxels_;
        if (grid.state[static_cast<std::size_t>((k * grid.ny + j) * grid.nx + i)] != kUnknown) ++target_known_;
      }
}

double ViewScorer::occupied_probability(long index) const { return listed_probability(grid_.occupied, index, 1.0); }

double ViewScorer::uncertain_free_probability(long index) const { return listed_probability(grid_.uncertain_free, index, 0.0); }

void ViewScorer::count_surface(long index, double visibility, RaySums& sums) const {
  const double h = binary_entropy(occupied_probability(index));
  sums.known_entropy += h;
  sums.occlusion_aware += visibility * h;
}

bool ViewScorer::pass_box_voxel(long index, std::uint32_t stamp, RayState& ray, ViewGain& out, RaySums& sums) {
  const std::uint8_t s = grid_.state[static_cast<std::size_t>(index)];
  if (s == kOccupied) {
    if (ray.previous_unknown_target >= 0) count_rear_side(ray.previous_unknown_target, stamp, out, sums);
    return true;
  }
  if (s == kUnknown) {
    ray.visibility *= 0.5;  // the run of unknown space goes on: a surface after it is still a rear side
    return false;
  }
  ray.previous_unknown_target = -1;
  return false;
}

bool ViewScorer::visit_target_voxel(long index, long mark, std::uint32_t stamp, RayState& ray, ViewGain& out, RaySums& sums) {
  if (!surface_.empty() && !surface_[static_cast<std::size_t>(mark)]) return pass_box_voxel(index, stamp, ray, out, sums);
  const std::uint8_t s = grid_.state[static_cast<std::size_t>(index)];
  const bool first = reached_[mark] != stamp;
  if (first) {
    reached_[mark] = stamp;
    ++out.target_reached;
  }
  if (s == kOccupied) {
    if (first) count_surface(index, ray.visibility, sums);
    if (ray.previous_unknown_target >= 0) count_rear_side(ray.previous_unknown_target, stamp, out, sums);
    return true;
  }
  if (s == kUnknown) {
    ray_unknown_.push_back(mark);
    if (first) {
      ++out.unknown_reached;
      sums.unknown_entropy += 1.0;
      sums.occlusion_aware += ray.visibility;
    }
    ray.previous_unknown_target = mark;
    ray.visibility *= 0.5;  // an unknown voxel is occupied with probability 0.5
    return false;
  }
  ray.previous_unknown_target = -1;
  // A free voxel seen free too few times to be settled (below OctoMap's clamp) is still
  // uncertain: its entropy counts, and it may hide what lies behind it.
  if (!grid_.uncertain_free.empty()) {
    if (const double p = uncertain_free_probability(index); p > 0.0) {
      if (first) {
        const double h = binary_entropy(p);
        sums.known_entropy += h;
        sums.occlusion_aware += ray.visibility * h;
      }
      ray.visibility *= 1.0 - p;
    }
  }
  return false;
}

// Rear side (Isler et al.): the ray crossed unknown space and met a surface, so it approached that
// surface from a side not yet seen.
void ViewScorer::count_rear_side(long previous, std::uint32_t stamp, ViewGain& out, RaySums& sums) {
  if (rear_[previous] != stamp) ++out.rear_side;
  for (long w : ray_unknown_) {
    if (rear_[w] == stamp || rear_[w] == stamp + 1) continue;
    rear_[w] = stamp + 1;
    sums.rear_entropy += 1.0;  // an unknown voxel: p = 0.5, one bit
  }
  rear_[previous] = stamp;
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

ViewScorer::Traversal ViewScorer::start(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter) const {
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  Traversal r;
  const Eigen::Vector3d start = g0 + (t_enter + 1e-9) * dg;
  for (int a = 0; a < 3; ++a) {
    r.ijk[a] = std::clamp(static_cast<long>(std::floor(start(a))), 0L, n[a] - 1);
    if (dg(a) > 0.0) {
      r.step[a] = 1;
      r.t_delta[a] = 1.0 / dg(a);
      r.t_next[a] = (r.ijk[a] + 1 - g0(a)) / dg(a);
    } else if (dg(a) < 0.0) {
      r.step[a] = -1;
      r.t_delta[a] = -1.0 / dg(a);
      r.t_next[a] = (r.ijk[a] - g0(a)) / dg(a);
    } else {
      r.step[a] = 0;
      r.t_delta[a] = r.t_next[a] = std::numeric_limits<double>::infinity();
    }
  }
  r.index = r.ijk[0] + r.ijk[1] * grid_.nx + r.ijk[2] * static_cast<long>(grid_.nx) * grid_.ny;
  return r;
}

namespace {

// The axis whose boundary is nearest, ties as in the reference walk (the later axis of a tie),
// written as selects rather than branches: which axis comes next is what a branch predictor
// guesses worst.
inline int nearest_axis(const double t[3]) {
  const bool x_before_y = t[0] < t[1];
  const double t_xy = x_before_y ? t[0] : t[1];
  const int a_xy = x_before_y ? 0 : 1;
  return t_xy < t[2] ? a_xy : 2;
}

}  // namespace

// The voxel-by-voxel walk crosses the boundaries of the three axes in the order of (t_next, the
// later axis first on a tie), and each axis's crossings come at t_next, t_next + t_delta, ... added
// one at a time: the walk is a merge of three sorted lists. Through a block where no voxel counts,
// (all free or all unknown, outside the target: no stop, no count, at most the visibility halved
// per voxel) only the crossing that leaves the block matters, and how many crossings of the other axes come
// before it. These are found from the same sums in the same order, so the state past the block is
// bit for bit the walk's, and the walk goes on from there exactly as the reference would.
bool ViewScorer::cross_block(Traversal& r, double t_exit, long& walked) const {
  constexpr long kSide = 1L << kBlockShift;
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  double crossing[3][kSide];  // crossing[a][c]: when axis a's boundary c + 1 is crossed, c + 1 < leave[a]
  long leave[3] = {0, 0, 0};  // the crossing of axis a that leaves the block (1-based)
  double t_leave[3];
  for (int a = 0; a < 3; ++a) {
    t_leave[a] = std::numeric_limits<double>::infinity();
    if (r.step[a] == 0) continue;
    const long block_lo = (r.ijk[a] >> kBlockShift) << kBlockShift;
    const long face = r.step[a] > 0 ? std::min(block_lo + kSide, n[a]) - 1 : block_lo;
    leave[a] = (face - r.ijk[a]) * r.step[a] + 1;
    double t = r.t_next[a];
    for (long c = 0; c + 1 < leave[a]; ++c) {
      crossing[a][c] = t;
      t += r.t_delta[a];
    }
    t_leave[a] = t;
  }
  const int e = nearest_axis(t_leave);
  if (t_leave[e] > t_exit) return false;
  walked = leave[e];  // the voxel the block was entered by, then one per crossing in it
  for (int a = 0; a < 3; ++a) {
    if (a == e || r.step[a] == 0) continue;
    long c = 0;  // crossings of axis a before the one that leaves the block
    while (c + 1 < leave[a] && (crossing[a][c] < t_leave[e] || (crossing[a][c] == t_leave[e] && a > e))) ++c;
    walked += c;
    r.ijk[a] += c * r.step[a];
    r.t_next[a] = c + 1 < leave[a] ? crossing[a][c] : t_leave[a];
  }
  r.ijk[e] += leave[e] * r.step[e];
  if (r.ijk[e] < 0 || r.ijk[e] >= n[e]) return false;
  r.t_next[e] = t_leave[e] + r.t_delta[e];
  r.index = r.ijk[0] + r.ijk[1] * grid_.nx + r.ijk[2] * static_cast<long>(grid_.nx) * grid_.ny;
  return true;
}

// The reference walk's result in three phases. The box of target voxels is convex in index
// space and each index moves one way along a ray, so a ray is in the target over one stretch.
// Before it, no voxel is in the target: only an occupied voxel (the ray stops, nothing counted,
// no unknown target voxel before it) and the visibility matter. In it, everything. Past it, only
// the first voxel can count (an occupied one ends a rear-side run); after that the reference
// resets its run and meets no target voxel again.
void ViewScorer::walk_ray(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter, double t_exit,
                          std::uint32_t stamp, ViewGain& out, RaySums& sums) {
  if (reached_.empty()) return;  // no target voxel in the grid: nothing to count
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  const long stride[3] = {1, grid_.nx, static_cast<long>(grid_.nx) * grid_.ny};
  const long mark_stride[3] = {1, span_[0], span_[0] * span_[1]};
  // Offsets from lo_ as unsigned: one compare per axis for "in the target's range".
  const unsigned long last[3] = {static_cast<unsigned long>(span_[0] - 1), static_cast<unsigned long>(span_[1] - 1),
                                 static_cast<unsigned long>(span_[2] - 1)};
  const auto in_range = [&](const long ijk[3], int a) { return static_cast<unsigned long>(ijk[a] - lo_[a]) <= last[a]; };
  Traversal r = start(g0, dg, t_enter);
  long* const ijk = r.ijk;
  // Crosses the nearest boundary; false when the ray ends there (t_exit or the grid's side).
  int a = 0;
  double tx = r.t_next[0], ty = r.t_next[1], tz = r.t_next[2];
  const auto advance = [&] {
    const bool x_before_y = tx < ty;
    const double t_xy = x_before_y ? tx : ty;
    const bool z = !(t_xy < tz);
    a = z ? 2 : (x_before_y ? 0 : 1);
    if ((z ? tz : t_xy) > t_exit) return false;
    ijk[a] += r.step[a];
    if (ijk[a] < 0 || ijk[a] >= n[a]) return false;
    r.index += r.step[a] * stride[a];
    tx += a == 0 ? r.t_delta[0] : 0.0;
    ty += a == 1 ? r.t_delta[1] : 0.0;
    tz += a == 2 ? r.t_delta[2] : 0.0;
    return true;
  };
  const std::uint8_t* const state = grid_.state.data();

  // Before the target. The visibility is 0.5^(unknown voxels walked): a power of two, halved
  // exactly (to 0 past 2^-1074 as ldexp rounds too), so a count of them gives it.
  long unknown_walked = 0;
  while (!(in_range(ijk, 0) && in_range(ijk, 1) && in_range(ijk, 2))) {
    if (const std::uint8_t b = block_of(ijk); b != kMixedBlock) {
      long walked = 0;
      r.t_next[0] = tx, r.t_next[1] = ty, r.t_next[2] = tz;
      if (!cross_block(r, t_exit, walked)) return;
      tx = r.t_next[0], ty = r.t_next[1], tz = r.t_next[2];
      if (b == kUnknownBlock) unknown_walked += walked;
      continue;
    }
    ++out.steps;
    const std::uint8_t s = state[r.index];
    if (s == kOccupied) return;
    if (s == kUnknown) ++unknown_walked;  // an unknown voxel is occupied with probability 0.5
    if (!advance()) return;
  }
  const double visibility = std::ldexp(1.0, -static_cast<int>(std::min(unknown_walked, 2000L)));

  // In the target.
  long mark = mark_of(ijk);
  RayState ray{visibility, -1};
  ray_unknown_.clear();
  for (;;) {
    ++out.steps;
    if (visit_target_voxel(r.index, mark, stamp, ray, out, sums)) return;
    if (!advance()) return;
    if (!in_range(ijk, a)) break;
    mark += r.step[a] * mark_stride[a];
  }

  // The first voxel past the target: only a surface right after unknown target space counts.
  ++out.steps;
  if (ray.previous_unknown_target >= 0 && state[r.index] == kOccupied) count_rear_side(ray.previous_unknown_target, stamp, out, sums);
}

ViewGain ViewScorer::score(const Pose& T_world_camera, const Intrinsics& K, Measure measure) {
  return score_with(T_world_camera, K, measure, &ViewScorer::walk_ray);
}

ViewGain ViewScorer::score_reference(const Pose& T_world_camera, const Intrinsics& K, Measure measure) {
  return score_with(T_world_camera, K, measure, &ViewScorer::walk_ray_reference);
}

ViewGain ViewScorer::score_with(const Pose& T_world_camera, const Intrinsics& K, Measure measure, Walk walk) {
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
      (this->*walk)(g0, dg, t_enter, t_exit, stamp, out, sums);
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
