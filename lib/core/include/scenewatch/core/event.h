#pragma once
/// Surprise events, the levels of the seed's hierarchy (Fig. 3.5) and their kinds.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"

namespace scenewatch {

enum class EventLevel { kMismatch, kPrediction, kImplausibility };

enum class EventKind {
  kObjectAppeared,    ///< no longer raised (kept for the wire format): the object list says what is there
  kObjectGone,        ///< no longer raised (kept for the wire format): kObjectRemoved says what left
  kAppearanceChange,  ///< image-based surprise (issue 4)
  kObjectAdded,       ///< geometric change detection (issue 5)
  kObjectRemoved,
  kObjectMoved,
  kFrozenDofMotion,   ///< implausible motion of a foreground object (issue 12)
  kObjectPromoted,    ///< a touched object moved by a hand became a foreground object (issue 12)
};

const char* to_string(EventLevel level);
const char* to_string(EventKind kind);

/// The pixel region of the frame an event arose in (bounding rectangle plus its pixel count).
struct PixelRegion {
  int x = 0, y = 0, width = 0, height = 0;
  std::uint32_t area = 0;  ///< pixels inside the region, <= width * height
};

struct Event {
  std::uint64_t id = 0;
  double stamp_s = 0.0;
  EventLevel level = EventLevel::kMismatch;
  EventKind kind = EventKind::kObjectAppeared;
  double score = 0.0;
  Aabb box_world;
  Eigen::Vector3d centroid_world = Eigen::Vector3d::Zero();
  std::optional<std::uint64_t> object_id;
  std::string detail;  ///< human-readable evidence
  /// Numeric evidence by name, e.g. "kl_peak_luminance", "area_px", "depth_diff_m".
  std::map<std::string, double> evidence;
  std::optional<PixelRegion> region;                 ///< where in the frame it arose
  std::optional<Eigen::Vector3d> displacement_world;  ///< OBJECT_MOVED: where it went minus where it was
  /// Indices of the event's points in the observation(s) it came from (e.g. BEFORE / AFTER of a
  /// diff, or the ingested frame's cloud as "after"). Empty when not applicable.
  std::vector<int> indices_before, indices_after;
  /// The pending changes this event confirmed (their ids while they were pending, issue 31). Not
  /// saved with the model: the ids count anew in each run of the daemon.
  std::vector<std::uint64_t> pending_ids;
};

}  // namespace scenewatch
