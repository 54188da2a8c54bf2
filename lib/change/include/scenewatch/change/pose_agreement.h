#pragma once
/// How well a frame's given pose agrees with the map it is compared with (issue 28). A pose error
/// moves every surface of the frame against the map together; noise does not, and a real change
/// moves one place. So the rigid motion that best explains the residuals between the frame's
/// surfaces and the map's (one robust point-to-plane least-squares step, as in ICP) measures the
/// pose's error in this frame, and every claim of change is weighed against it
/// (change::map_tolerance_m). Nothing is corrected: the frame keeps its pose.
#include <cstddef>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/depth_validity.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::change {

struct PoseAgreement {
  std::size_t samples = 0;        ///< rays that met a surface of the map near their depth
  /// The rigid motion of world points that best aligns the frame with the map (identity when
  /// nothing was measured): the given pose's error, undone.
  Pose correction = Pose::Identity();
  double translation_m = 0.0;     ///< how far it moves the camera
  double rotation_deg = 0.0;      ///< ... and turns it
  double rms_shift_m = 0.0;       ///< how far it moves the sampled points, RMS
  double rms_residual_m = 0.0;    ///< point-to-plane residual before the fit, robust RMS
  /// How far the misalignment has moved a point of the frame, metres.
  double shift_at(const Eigen::Vector3d& p_world) const;
};

/// Casts every `step_px`-th pixel's ray (of every `step_px`-th row) among the trusted ones through
/// the grid near its depth, takes the map's surface there (the middle of the run of occupied
/// voxels the ray meets), and fits the camera motion that best explains the point-to-plane
/// residuals (normals from the frame's own depth; Huber weights, three rounds). Fewer than 100
/// samples, or a fit the samples do not constrain, measure nothing (zero misalignment).
PoseAgreement pose_agreement(const background::DenseGrid& grid, const Cloud& points_camera, const Pose& T_world_camera,
                             const Intrinsics& K, const DepthValidity& trusted, const SensorModel& sensor, int step_px = 8);

}  // namespace scenewatch::change
