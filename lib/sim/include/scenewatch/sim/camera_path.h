#pragma once
/// Camera trajectories: static, a circle (arc) around a target, hand-held (smooth shake about a
/// fixed view) and keyframed paths. Cameras look at a target with world z up; camera axes are
/// x right, y down, z forward.
#include <cstdint>
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/look_at.h"

namespace scenewatch::sim {

/// Kind of camera trajectory.
enum class CameraPathKind { kStatic, kCircle, kHandheld, kKeyframes };

/// Printable name ("static", "circle", "handheld", "keyframes").
const char* to_string(CameraPathKind kind);

/// One key of a keyframed camera path, at a time given in frames of the phase.
struct CameraKey {
  double frame = 0.0;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_world = Eigen::Vector3d::Zero();
};

/// A camera trajectory over one phase.
struct CameraPath {
  CameraPathKind kind = CameraPathKind::kStatic;
  Eigen::Vector3d position_world = Eigen::Vector3d(1.0, 0.0, 1.5);  ///< static, handheld
  Eigen::Vector3d target_world = Eigen::Vector3d(0.0, 0.0, 0.75);   ///< look-at point (all kinds)
  // circle: the camera moves on a horizontal circle about target_world's vertical axis.
  double radius_m = 1.3;
  double height_m = 1.5;          ///< camera z in the world
  double start_deg = 0.0;         ///< angle of the first frame, from world +x, counter-clockwise
  double arc_deg = 360.0;         ///< swept angle over the phase (negative: clockwise)
  double wobble_m = 0.0;          ///< radial and vertical sinusoidal deviation (a robot's path)
  double wobble_cycles = 3.0;     ///< periods of the wobble over the phase
  // handheld: smooth shake about position/target.
  double shake_m = 0.01;
  double shake_deg = 1.0;
  // keyframes: positions and targets interpolated (smoothstep between keys).
  std::vector<CameraKey> keys;
};


/// T_world_camera at time `frame` (in frames of a phase of `frame_count` frames; fractional
/// times allowed). `seed` drives the hand-held shake.
Pose camera_pose(const CameraPath& path, double frame, int frame_count, std::uint64_t seed);

}  // namespace scenewatch::sim
