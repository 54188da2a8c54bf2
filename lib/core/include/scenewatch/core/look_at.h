#pragma once
/// A camera pose that looks at a point: what the simulator's camera paths and the view planner's
/// candidates both need.
#include <Eigen/Core>

#include "scenewatch/core/geometry.h"

namespace scenewatch {

/// T_world_camera of a camera at `eye` looking at `target` (x right, y down, z forward, as the
/// sensor's frame), with the image's up as close to `up_world` as it gets. Looking straight along
/// `up_world`, x is taken across the world's y axis (else its x axis); `eye` on `target` looks
/// along the world's x axis.
Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
             const Eigen::Vector3d& up_world = Eigen::Vector3d::UnitZ());

}  // namespace scenewatch
