#pragma once
/// A scenario: the static scene (room, table, objects), the sensor, and one or more phases, each
/// with a camera trajectory, an optional hand and the changes made to the scene before it. The
/// YAML form is described in sample_clouds/README.md and parsed by scenario_yaml.h.
#include <cstdint>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/sim/camera_path.h"
#include "scenewatch/sim/hand.h"
#include "scenewatch/sim/material.h"
#include "scenewatch/sim/raycaster.h"
#include "scenewatch/sim/sensor_model.h"
#include "scenewatch/sim/shapes.h"

namespace scenewatch::sim {

/// Labels of the instance-label image. Objects get id * kObjectLabelFactor (mOSD: id = label / 10).
inline constexpr std::uint16_t kLabelBackground = 0;  ///< floor, walls, ceiling, nothing
inline constexpr std::uint16_t kLabelTable = 1;
inline constexpr std::uint16_t kLabelHand = 2;        ///< hand and forearm
inline constexpr std::uint16_t kObjectLabelFactor = 10;
inline constexpr int kMaxObjectId = 6553;             ///< id * 10 must fit in 16 bits

/// A movable object: a primitive with an appearance and a pose.
struct SceneObject {
  int id = 0;                              ///< >= 1; its label is id * 10
  std::string name;
  Shape shape;
  Material material;
  Pose T_world_object = Pose::Identity();  ///< origin at the centre of the base, z up the axis
  /// Label written for this object.
  std::uint16_t label() const { return static_cast<std::uint16_t>(id * kObjectLabelFactor); }
};

/// The table: a top (box) on four cylindrical legs. Its top surface is the support plane.
struct TableSpec {
  bool present = true;
  Eigen::Vector2d center_world = Eigen::Vector2d::Zero();
  double yaw_deg = 0.0;
  Eigen::Vector2d size_m = Eigen::Vector2d(1.2, 0.8);  ///< along the table's x and y
  double height_m = 0.75;                              ///< world z of the top surface
  double thickness_m = 0.03;
  double leg_radius_m = 0.025;
  double leg_inset_m = 0.06;                           ///< legs' distance from the top's edges
  Material top, legs;
  TableSpec();
  /// The support plane's frame: origin at the centre of the top surface, z up, x along the table.
  Pose T_world_support() const;
};

/// A move of an object between phases.
struct ObjectMove {
  int id = 0;
  Pose T_world_object = Pose::Identity();
};

/// Changes applied to the scene before a phase starts.
struct SceneChanges {
  std::vector<int> remove;          ///< ids of objects taken away
  std::vector<SceneObject> add;     ///< new objects
  std::vector<ObjectMove> move;     ///< objects put somewhere else
};

/// One recorded sequence.
struct PhaseSpec {
  std::string name = "main";
  int frames = 1;
  CameraPath camera;
  HandSpec hand;
  SceneChanges changes;  ///< applied before this phase (not allowed on the first phase)
};

/// Thresholds above which a degree of freedom counts as moved in the ground truth.
struct DofThresholds {
  double translation_m = 0.005;
  double rotation_deg = 2.0;
};

/// A full scenario.
struct Scenario {
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  Intrinsics intrinsics{525.0, 525.0, 319.5, 239.5, 640, 480};
  double frame_rate_hz = 30.0;
  Room room;
  Lighting lighting;
  TableSpec table;
  std::vector<SceneObject> objects;  ///< the scene at the start of the first phase
  std::vector<PhaseSpec> phases;
  SensorConfig sensor;
  DofThresholds dof_thresholds;
  double touch_tolerance_m = 0.01;   ///< hand-object distance that counts as a touch
  Scenario();
};

/// Checks ids (unique, 1..kMaxObjectId), sizes and phases; the message names the problem.
Status validate(const Scenario& scenario);

/// Resizes the image to width x height, scaling the intrinsics with it.
Scenario with_resolution(Scenario scenario, int width, int height);

/// Sets the frame count of every phase to `frames`; hand and camera keys keep their place in
/// time (they are given in frames of the declared count and rescaled by the simulator).
Scenario with_frames(Scenario scenario, int frames);

}  // namespace scenewatch::sim
