#pragma once
/// The frame's points near a place, without agents and without the supporting planes' surfaces:
/// a registration target and the pixels and world points around a tracked object. Private to the
/// foreground module.
#include <vector>

#include "scenewatch/foreground/foreground_tracker.h"

namespace scenewatch::foreground {

struct Crop {
  Cloud target;                          ///< world frame, thinned to one point per voxel
  std::vector<int> pixels;               ///< every kept pixel's index in the frame
  std::vector<Eigen::Vector3d> points;   ///< and its world position
};

/// The frame's points within `radius` of `centre_world`, off the agents (f.hands) and off the
/// near-horizontal supporting planes (f.planes); the target keeps one point per `voxel`.
Crop crop(const FrameView& f, const Eigen::Vector3d& centre_world, double radius, double voxel);

}  // namespace scenewatch::foreground
