#pragma once
/// What the ontology says about one tracked object (WorkingMemory::describe_objects): its class
/// with a score, the class's primitive fitted to it and its grasps. What GetObjects puts in
/// Object.ontology, without the ontology's working (candidates, the fit, the completed surface).
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
};

/// Told of each new description (WorkingMemory::describe_objects), with the object as described.
using DescribedCallback = std::function<void(const TrackedObject&, const ObjectClassInfo&)>;

}  // namespace scenewatch::pipeline
