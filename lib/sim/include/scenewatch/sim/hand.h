#pragma once
/// The human hand and forearm: skin-coloured capsules in the hand frame, and the hand's keyframed
/// trajectory (reach, touch, grasp, carry, release).
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/sim/material.h"
#include "scenewatch/sim/shapes.h"

namespace scenewatch::sim {

/// One key of the hand's trajectory. The hand frame has its origin at the palm's centre, x along
/// the fingers, y towards the thumb, z out of the back of the hand; the forearm extends along -x.
struct HandKey {
  double frame = 0.0;                                       ///< time in frames of the phase
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();  ///< palm centre
  double roll_deg = 0.0, pitch_deg = 0.0, yaw_deg = 0.0;    ///< R = Rz(yaw) Ry(pitch) Rx(roll)
  int grasp_id = 0;    ///< > 0: the hand grasps this object at this key; it then moves with the hand
  int release_id = 0;  ///< > 0: the hand lets go of this object at this key
};

/// A hand in a phase; no keys means no hand.
struct HandSpec {
  std::vector<HandKey> keys;
  Material skin;       ///< defaults to a skin tone with a faint noise texture
  double scale = 1.0;  ///< size relative to an adult's hand
  HandSpec();
};

/// One capsule of the hand model, placed in the hand frame.
struct HandPart {
  Shape shape;
  Pose T_hand_part = Pose::Identity();
};

/// The capsules of palm, fingers, thumb and forearm.
std::vector<HandPart> hand_parts(double scale);

/// A capsule from a to b with radius r: the shape and its pose (z along b - a).
HandPart capsule_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius_m);

/// The rotation of a key (ZYX Euler angles in degrees).
Eigen::Matrix3d rotation_from_rpy_deg(double roll_deg, double pitch_deg, double yaw_deg);

/// T_world_hand at a time (smoothstep between keys, slerp of the orientation; clamped to the
/// first and last key). The spec must have keys sorted by frame.
Pose hand_pose(const HandSpec& hand, double frame);

}  // namespace scenewatch::sim
