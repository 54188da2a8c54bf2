#pragma once
/// Per-point observation histories for the seed's planner (D5.1 3.1.2.5): which of the appearance
/// memory's keyframes saw each point, read from their depth images. The memory keeps no history per
/// point; a keyframe is a posed depth image, so whether it saw a point is a projection and a depth
/// comparison. Stateless functions: thread safe.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/background/appearance.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::planning {

/// When a keyframe's depth at a point's pixel counts as that point: within sigma_factor axial
/// noises of the sensor at that range, plus a map voxel (the points are thinned to voxels, so a
/// point may sit anywhere in its voxel).
struct DepthAgreement {
  SensorModel sensor;
  double sigma_factor = 3.0;   ///< as the change detector's (change.sigma_factor)
  double resolution_m = 0.02;  ///< the map's voxel edge (background.resolution_m)
  /// The tolerance at range z, metres.
  double tolerance_m(double z_m) const { return sigma_factor * sensor.sigma_z(z_m) + resolution_m; }
};

/// For each point, the camera centres (world) of the keyframes that observed it: the point lies in
/// front of the keyframe's camera, projects inside its image off the sensor's untrusted border
/// (sensor.border_px), and the keyframe's depth at that pixel agrees with the point's depth within
/// agreement.tolerance_m. A point behind a nearer surface, or where the keyframe has no depth, was
/// not observed by it.
std::vector<std::vector<Eigen::Vector3d>> observing_camera_centres(
    const std::vector<Eigen::Vector3d>& points_world,
    const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes, const DepthAgreement& agreement);

/// Points on the faces of an object's box but the one facing most down (where it rests on its
/// support), about spacing_m apart: the candidates for its surface. The faces no keyframe saw
/// stand for the unseen side, which the memory has no points of.
std::vector<Eigen::Vector3d> box_surface_samples(const OrientedBox& box_world, const Eigen::Vector3d& up_world,
                                                 double spacing_m);

}  // namespace scenewatch::planning
