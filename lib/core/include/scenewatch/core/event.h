#pragma once
/// Surprise events, the levels of the seed's hierarchy (Fig. 3.5) and their kinds.
#include <cstdint>
#include <optional>
#include <string>

#include "scenewatch/core/geometry.h"

namespace scenewatch {

enum class EventLevel { kMismatch, kPrediction, kImplausibility };

enum class EventKind {
  kObjectAppeared,    ///< a cluster with no match in the memory
  kObjectGone,        ///< a remembered object whose space is now seen free
  kAppearanceChange,  ///< image-based surprise (issue 4)
  kObjectAdded,       ///< geometric change detection (issue 5)
  kObjectRemoved,
  kObjectMoved,
  kFrozenDofMotion,   ///< implausible motion
};

const char* to_string(EventLevel level);
const char* to_string(EventKind kind);

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
};

}  // namespace scenewatch
