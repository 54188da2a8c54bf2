#pragma once
/// Volumetric information gain of a view on the memory's map: rays through the camera's image cast
/// through a dense copy of the map (background::DenseGrid), stopped at occupied voxels, and what
/// they reach in the target box counted by one of the measures of Isler, Sabzevari, Delmerico and
/// Scaramuzza, "An information gain formulation for active volumetric 3D reconstruction" (ICRA
/// 2016).
#include <cstdint>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"

namespace scenewatch::planning {

enum class Measure {
  kUnobserved,       ///< Isler's unobserved voxel: distinct unknown target voxels the rays reach
  kRearSide,         ///< Isler's rear side voxel: unknown target voxels met just before an occupied one
  kRearSideEntropy,  ///< Isler's rear side entropy: the entropy of the unknown target voxels on rays that end
                     ///< on an occupied voxel after unknown space (the back of what has been seen)
  kOcclusionAware,   ///< Isler's occlusion aware: sum of entropy times visibility (prod of 1 - p before)
  kVisible,          ///< target voxels the rays reach whatever their state (to confirm or dismiss an event)
};
const char* to_string(Measure measure);
/// Parses the name to_string gives; an error listing the names otherwise.
Result<Measure> parse_measure(const std::string& name);

struct VolumetricConfig {
  int rays_x = 80;            ///< rays across the image (evenly spaced pixel centres)
  int rays_y = 60;            ///< rays down the image
  double max_range_m = 4.5;   ///< depth (z) at which rays end (the sensor's range)
};

/// Checks the numbers; the message names the key.
Status validate(const VolumetricConfig& config);

/// What one candidate view would see of the target.
struct ViewGain {
  double gain = 0.0;                ///< the measure's value
  std::size_t unknown_reached = 0;  ///< distinct unknown target voxels on the rays
  std::size_t rear_side = 0;        ///< distinct unknown target voxels just before an occupied voxel
  std::size_t target_reached = 0;   ///< distinct target voxels on the rays, any state
  double entropy_bits = 0.0;        ///< summed entropy of the distinct target voxels reached
  double expected_coverage = 0.0;   ///< fraction of the target's voxels known after the view
  std::size_t steps = 0;            ///< voxels whose state a ray read, all rays (score() stops a ray at
                                    ///< the first voxel past the target, score_reference() at the clip)
};

/// Scores views against one grid and one target box. Keeps per-voxel marks between calls: NOT
/// thread safe (one scorer per thread); the grid must outlive it and not change.
class ViewScorer {
 public:
  /// `grid` should hold the target and every camera position (rays leaving it stop there).
  /// `surface_world` (optional) narrows the target to a surface: its voxels are those of the box
  /// holding one of these points (an object's completed primitive, its unseen side included),
  /// and only they count. The box's other voxels still stop rays (occupied) and dim them
  /// (unknown), and unknown space between a surface voxel and the occupied voxel that ends the
  /// ray keeps it a rear side. Points outside the box are ignored. Empty: every voxel of the box.
  ViewScorer(const background::DenseGrid& grid, const Aabb& target_world, VolumetricConfig config = {},
             const std::vector<Eigen::Vector3d>& surface_world = {});
  ViewGain score(const Pose& T_world_camera, const Intrinsics& K, Measure measure);
  /// The same gains by the straightforward walk (every voxel up to the clip with the full
  /// bookkeeping): slower, the oracle of score() in the tests.
  ViewGain score_reference(const Pose& T_world_camera, const Intrinsics& K, Measure measure);
  std::size_t target_voxels() const { return target_voxels_; }
  std::size_t target_known() const { return target_known_; }
  /// Fraction of the target's voxels known (free or occupied) now.
  double coverage() const { return target_voxels_ ? static_cast<double>(target_known_) / target_voxels_ : 0.0; }

 private:
  /// score()'s running sums over the rays of one view.
  struct RaySums {
    double unknown_entropy = 0.0, rear_entropy = 0.0, occlusion_aware = 0.0, known_entropy = 0.0;
  };
  /// One ray's 3D-DDA state (Amanatides & Woo): voxel, grid index, and the ray parameter (metres)
  /// at the next boundary per axis, advanced by repeated addition of t_delta.
  struct Traversal {
    long ijk[3], step[3], index;
    double t_next[3], t_delta[3];
  };
  using Walk = void (ViewScorer::*)(const Eigen::Vector3d&, const Eigen::Vector3d&, double, double, std::uint32_t, ViewGain&,
                                    RaySums&);
  ViewGain score_with(const Pose& T_world_camera, const Intrinsics& K, Measure measure, Walk walk);
  Traversal start(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter) const;
  /// Crosses the uniform block holding r.ijk (see block_) in one go, to the first voxel past it,
  /// with the traversal state the voxel-by-voxel walk would have there; the voxels walked in the
  /// block into `walked`. False when the ray ends in the block or leaves the grid.
  bool cross_block(Traversal& r, double t_exit, long& walked) const;
  /// The block_ entry of voxel (i, j, k).
  std::uint8_t block_of(const long ijk[3]) const {
    return block_[static_cast<std::size_t>(((ijk[2] >> kBlockShift) * blocks_[1] + (ijk[1] >> kBlockShift)) * blocks_[0] +
                                           (ijk[0] >> kBlockShift))];
  }
  /// The mark slot of target voxel (i, j, k): reached_ and rear_ cover the target box only.
  long mark_of(const long ijk[3]) const { return ((ijk[2] - lo_[2]) * span_[1] + (ijk[1] - lo_[1])) * span_[0] + ijk[0] - lo_[0]; }
  double occupied_probability(long index) const;
  /// A free voxel's occupancy probability while its belief is not settled (the grid's
  /// uncertain_free); 0 for a settled one.
  double uncertain_free_probability(long index) const;
  /// An occupied target voxel reached for the first time in this call: its entropy into the sums.
  void count_surface(long index, double visibility, RaySums& sums) const;
  /// One ray's running state: the visibility (prod of 1 - p so far) and the mark slot of the
  /// voxel just walked when it is unknown and in the target, else -1.
  struct RayState {
    double visibility = 1.0;
    long previous_unknown_target = -1;
  };
  /// A voxel of the target's box that is not on the target's surface (surface_ given): it stops
  /// or dims the ray and keeps an unknown run going, and counts nothing itself. True when the
  /// ray stops there.
  bool pass_box_voxel(long index, std::uint32_t stamp, RayState& ray, ViewGain& out, RaySums& sums);
  /// A target voxel (grid index, mark slot) on a ray: counts it; true when the ray stops there.
  bool visit_target_voxel(long index, long mark, std::uint32_t stamp, RayState& ray, ViewGain& out, RaySums& sums);
  /// A ray met a surface right after the unknown target voxel in mark slot `previous`: Isler's
  /// rear side, and the rear-side entropy of the ray's unknown target voxels (ray_unknown_).
  void count_rear_side(long previous, std::uint32_t stamp, ViewGain& out, RaySums& sums);
  /// The part of a ray (from g0 along dg, grid units) worth walking, in metres; false: none.
  bool clip_ray(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_max, double& t_enter, double& t_exit) const;
  /// Walks one clipped ray voxel by voxel, counting into `out` and `sums`: before the target only
  /// the stop at a surface and the visibility, in the target everything, past it one voxel.
  void walk_ray(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter, double t_exit, std::uint32_t stamp,
                ViewGain& out, RaySums& sums);
  /// walk_ray's straightforward form: every voxel to t_exit, each tested for everything.
  void walk_ray_reference(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter, double t_exit, std::uint32_t stamp,
                ViewGain& out, RaySums& sums);
  const background::DenseGrid& grid_;
  VolumetricConfig config_;
  long lo_[3] = {0, 0, 0}, hi_[3] = {-1, -1, -1};  ///< the target's voxel index range, inclusive
  long span_[3] = {0, 0, 0};                        ///< hi_ - lo_ + 1, at least 0
  std::size_t target_voxels_ = 0, target_known_ = 0;
  /// Empty-space skipping: blocks of 2^kBlockShift voxels a side (clipped by the grid), outside
  /// the target, all free or all unknown; built once per scorer.
  static constexpr int kBlockShift = 3;
  static constexpr std::uint8_t kMixedBlock = 0, kFreeBlock = 1, kUnknownBlock = 2;
  long blocks_[3] = {0, 0, 0};
  std::vector<std::uint8_t> block_;
  std::vector<std::uint32_t> reached_, rear_;       ///< marks per target voxel (mark_of): == stamp_ when counted in this call
  std::vector<std::uint8_t> surface_;               ///< per mark slot, 1: on the target's surface; empty: all are
  std::uint32_t stamp_ = 0;
  std::vector<long> ray_unknown_;                   ///< scratch: one ray's unknown target voxels (mark slots)
};

}  // namespace scenewatch::planning
