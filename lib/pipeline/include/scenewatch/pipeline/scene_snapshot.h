#pragma once
/// The scene as readers see it: planes, objects (background and foreground), hands, each
/// object's points and the changes seen but not yet confirmed, published by WorkingMemory after
/// each frame.
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/change/pending_change.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::pipeline {

/// A hand (with its forearm) as a planner sees it: where not to reach.
struct HandSeen {
  Aabb box_world;
  Eigen::Vector3d tip_world = Eigen::Vector3d::Zero();
  double score = 0.0;
  std::size_t pixels = 0;
  bool enters_from_border = false;
};

/// The hands and the person of the last frame that had colour.
struct HandsSeen {
  std::uint64_t frame_index = 0;
  double stamp_s = 0.0;
  std::vector<HandSeen> hands;
  std::size_t person_pixels = 0;
  std::optional<Aabb> person_box_world;
};

/// A change seen but not yet confirmed (not yet an event), with the name of the camera that saw it.
struct PendingChangeSeen {
  change::PendingChange change;
  std::string camera;  ///< as the frames named it ("" the unnamed camera)
};

/// An immutable view of the scene, swapped atomically after each frame: readers never wait for
/// a frame being processed.
struct SceneSnapshot {
  std::uint64_t frames_processed = 0;
  std::vector<Plane> planes;            ///< from the last frame, world frame
  std::vector<TrackedObject> objects;   ///< background objects, then foreground ones (foreground set), world frame
  HandsSeen hands;
  /// Each object's points (world, thinned) by id: the last observation of a background object, the
  /// posed model of a foreground one. For what describes objects (the ontology's describe()).
  std::map<std::uint64_t, std::shared_ptr<const std::vector<Eigen::Vector3d>>> points;
  Eigen::Vector3d up_world = Eigen::Vector3d::UnitZ();      ///< the support's up (config or largest plane)
  Eigen::Vector3d camera_world = Eigen::Vector3d::Zero();   ///< where the last frame was taken
  double last_stamp_s = 0.0;
  /// The geometric change detector's unconfirmed candidates, then the appearance-only ones, as
  /// this frame left them: targets for the view that confirms or dismisses them (issue 31).
  std::vector<PendingChangeSeen> pending;
};

}  // namespace scenewatch::pipeline

