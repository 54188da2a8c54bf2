#pragma once
/// Two single observations: which objects were added, removed or moved from BEFORE to AFTER.
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/change/objects.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::change {

/// How the pair was compared.
enum class DiffMethod {
  kSameCamera,  ///< organized, equal size, same pose: per-pixel depth reasoning
  kMap,         ///< BEFORE inserted into an occupancy map, AFTER compared against it
};
const char* to_string(DiffMethod method);

struct DiffOptions {
  Config change;
  background::Config map;  ///< for the map path
  /// Segmentation of each frame, in its camera frame, for whole-object completion
  /// (change.complete_objects).
  segmentation::Config segmentation;
  /// Force the map path even for same-camera pairs.
  bool force_map = false;
};

struct DiffResult {
  DiffMethod method = DiffMethod::kSameCamera;
  std::vector<ObjectChange> changes;
  std::vector<Event> events;  ///< one per change, ids from 1; indices_before / indices_after filled
  Mismatch mismatch;          ///< raw evidence
  double total_ms = 0;
  double completion_ms = 0;  ///< of total_ms: segmenting both frames and completing the changes
};

/// Compares two frames (clouds in their camera frames, with optional poses and intrinsics; no
/// pose = the camera frame is the world). Errors name the problem: empty or all-NaN cloud,
/// non-rigid pose, intrinsics that do not fit the cloud.
Result<DiffResult> diff(const Frame& before, const Frame& after, const DiffOptions& options = {});

}  // namespace scenewatch::change
