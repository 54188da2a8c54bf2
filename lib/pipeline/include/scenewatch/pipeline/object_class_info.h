#pragma once
/// What the ontology says about one tracked object (WorkingMemory::describe_objects): its class
/// with a score, the class's primitive fitted to it, its grasps and its completed surface.
/// GetObjects puts all but the surface in Object.ontology (not the ontology's working either: the
/// candidates, the fit); NextBestView plans to see the surface.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/scene.h"
#include "scenewatch/ontology/describe.h"

namespace scenewatch::pipeline {

/// One object's description (ontology::ObjectDescription's results, world frame).
struct ObjectClassInfo {
  std::string class_name = ontology::kUnknownClass;  ///< the best accepted class, or "unknown"
  double score = 0;                                   ///< its score, 0 for unknown
  /// The class's primitive fitted to the object; unknown: the best shape fitted for the classes, if
  /// any (ObjectDescription::primitive); none when the object could not be fitted at all.
  std::optional<ontology::ShapeFit> primitive;
  std::vector<ontology::GraspPose> grasps;  ///< the class's grasps on its primitive (none for unknown)
  /// The class's primitive's whole surface, its unseen side included (ontology::complete_surface,
  /// world frame, the describer's completion spacing apart); empty for unknown.
  std::vector<Eigen::Vector3d> completed_surface_world;
};

/// Told of each new description (WorkingMemory::describe_objects), with the object as described.
using DescribedCallback = std::function<void(const TrackedObject&, const ObjectClassInfo&)>;

}  // namespace scenewatch::pipeline
