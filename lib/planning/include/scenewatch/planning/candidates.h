#pragma once
/// Where the camera may go: candidate camera poses from a constraint (a sphere or spherical shell
/// around the target, a cap above the table, or a list of reachable poses).
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/look_at.h"
#include "scenewatch/core/result.h"

namespace scenewatch::planning {

enum class ConstraintKind {
  kSphere,  ///< on the sphere |x - center| = radius_max_m
  kShell,   ///< between radius_min_m and radius_max_m
  kCap,     ///< on the sphere, within max_polar_deg of `up` (a dome above the table)
  kList,    ///< exactly the given poses
};
const char* to_string(ConstraintKind kind);

/// A constraint on the camera's position; sampled poses look at `look_at_world` when set, else at
/// the centre.
struct ViewConstraint {
  ConstraintKind kind = ConstraintKind::kSphere;
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();
  double radius_min_m = 0.5;     ///< shell only
  double radius_max_m = 0.8;     ///< sphere, cap: the radius; shell: the outer radius
  Eigen::Vector3d up_world = Eigen::Vector3d::UnitZ();
  double max_polar_deg = 70.0;   ///< cap only: largest angle between `up` and the view position
  int samples = 64;              ///< sphere, shell, cap: how many candidates
  std::vector<Pose> poses;       ///< list only: T_world_camera
};

/// Checks the numbers; the message names the field.
Status validate(const ViewConstraint& constraint);


/// `count` nearly uniform unit directions (a Fibonacci sphere), deterministic.
std::vector<Eigen::Vector3d> fibonacci_directions(int count);

/// The candidate poses of a constraint, each looking at `target_world`. Deterministic: the same
/// constraint gives the same poses.
Result<std::vector<Pose>> candidate_poses(const ViewConstraint& constraint, const Eigen::Vector3d& target_world);

}  // namespace scenewatch::planning
