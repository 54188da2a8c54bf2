#pragma once
/// Where a foreground object's point model lies in a frame: ICP from its last pose (PCL), then the
/// turn about the vertical searched by colour, so that a turn about a symmetry axis (a printed cup
/// turned about its axis) is seen from its texture when the geometry alone cannot tell.
#include <cstddef>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::foreground {

struct RegistrationConfig {
  double max_distance_m = 0.02;    ///< first correspondence distance; halved twice while it converges
  double inlier_m = 0.01;          ///< a model point within this of the frame counts as seen
  /// Metres one full colour difference (0..1 per channel) is worth in ICP's correspondences; 0: by
  /// position only. Off: on the simulator's cup it lost the turn about the axis that the colour
  /// search below follows (worst 56 against 14 degrees of error), and it is slower.
  double colour_weight_m = 0.0;
  int iterations = 8;                ///< per correspondence gate, at most
  double converged_m = 0.0002;       ///< a gate ends when an iteration moves the model less than this...
  double converged_deg = 0.05;       ///< ...and turns it less than this
  double min_inlier_fraction = 0.35;  ///< of the model points that face the camera
  std::size_t min_inliers = 40;
  /// After ICP, turns about the vertical through the model's centre are searched in steps of
  /// `spin_step_deg` up to this far either way, scored by colour: ICP's pull on a turn about a
  /// symmetry axis (a cup's) is geometric and hence nil. 0: no search.
  double spin_search_deg = 8.0;
  double spin_step_deg = 2.0;
};

struct Registration {
  bool ok = false;
  Pose T_world_object = Pose::Identity();
  std::size_t inliers = 0;          ///< model points with a frame point within inlier_m
  double inlier_fraction = 0.0;     ///< of the model points that face the camera
  double rmse_m = 0.0;              ///< of the inliers
};

/// Registers `model` (points in the object frame, with colour) to `target` (frame points in the
/// world frame, already cropped to the region where the object can be) starting from `T_guess`.
/// `camera_world` is where the camera is: model points on the far side of the object are not
/// expected to be seen.
Registration register_model(const Cloud& model, const Cloud& target, const Pose& T_guess,
                            const Eigen::Vector3d& camera_world, const RegistrationConfig& config,
                            const Eigen::Vector3d& up_world = Eigen::Vector3d::UnitZ());

}  // namespace scenewatch::foreground
