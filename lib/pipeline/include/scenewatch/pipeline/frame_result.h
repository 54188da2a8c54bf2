#pragma once
/// What WorkingMemory::process() made of one frame: the pose used, planes, objects, events and
/// the time each stage took.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/pipeline/surprise_result.h"

namespace scenewatch::pipeline {

/// What one frame produced.
struct FrameResult {
  std::uint64_t frame_index = 0;
  std::size_t points = 0;               ///< valid points in the frame (all of them, whatever was inserted)
  /// The pose the memory used and how it was found. A frame whose camera is lost changed nothing
  /// and raised no event.
  localization::Localization localization;
  std::vector<Plane> planes;            ///< world frame
  std::vector<ObjectCluster> objects;   ///< world frame, indices into the frame's cloud
  std::vector<Event> events;
  /// What went into the map: fewer points than the frame's while a change is pending (its points
  /// wait until it is confirmed or dropped).
  background::InsertStats insert_stats;
  std::shared_ptr<const SurpriseResult> surprise;  ///< null: the frame had no pose or no keyframes existed yet
  double segment_ms = 0, insert_ms = 0, surprise_ms = 0, change_ms = 0, total_ms = 0;
  double hands_ms = 0, foreground_ms = 0;  ///< hand detection; foreground registration and promotion
  /// Wall time of the three parts side by side (segmentation, surprise, change + insertion), and
  /// of what follows them on one core (foreground, fusion, tracker, snapshot publication).
  double parallel_ms = 0, after_ms = 0;
  std::size_t hands = 0;                   ///< hands found in the frame
  std::size_t change_candidates = 0;  ///< changes seen but not yet confirmed
};

}  // namespace scenewatch::pipeline
