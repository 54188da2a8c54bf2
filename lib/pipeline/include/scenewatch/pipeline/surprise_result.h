#pragma once
/// What the appearance stage makes of one observation: the surprise map and its regions.
#include <cstddef>
#include <vector>

#include "scenewatch/core/event.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::pipeline {

/// The image-based surprise of one observation against the appearance memory.
struct SurpriseResult {
  surprise::SurpriseMap map;
  std::vector<Event> events;  ///< APPEARANCE_CHANGE regions (ids set only when emitted by process())
  std::size_t reference_views = 0;
  /// The memory knows this view from an earlier visit: a keyframe within twice the keyframe
  /// spacing, taken at least `surprise.familiar_after_frames` frames before. Only then may appearance alone
  /// report a change (a view seen for the first time differs in ways that are not change:
  /// reflections, transparency, what was hidden before).
  bool familiar_view = false;
  /// Pixels of the expected view that described objects' completed surfaces set (nearer than the
  /// mesh or where it had none; WorkingMemory::set_known_surface).
  std::size_t known_surface_pixels = 0;
  Pose T_world_camera = Pose::Identity();
  Intrinsics intrinsics;
  double stamp_s = 0.0;
  double ms = 0.0;
};

}  // namespace scenewatch::pipeline
