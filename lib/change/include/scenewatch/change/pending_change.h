#pragma once
/// Changes seen but not yet confirmed (issue 31, "Attention"): the persistence filter's geometric
/// candidates and the event fusion's appearance candidates, each with an id a planner can target
/// ("the view that best confirms or dismisses it") while it is pending.
#include <atomic>
#include <cstdint>

#include "scenewatch/core/geometry.h"

namespace scenewatch::change {

enum class PendingKind { kAdded, kRemoved, kAppearance };

/// One unconfirmed candidate as the outside sees it.
struct PendingChange {
  std::uint64_t id = 0;  ///< kept while it is matched frame to frame; never given twice (PendingIds)
  PendingKind kind = PendingKind::kAdded;
  Aabb box_world;        ///< of its latest sighting
  Eigen::Vector3d centroid_world = Eigen::Vector3d::Zero();
  int hits = 0;          ///< frames that saw it so far
  /// Frames it needs to be confirmed. hits may reach it before it fires: a ready half of a move
  /// waits a few frames for its partner.
  int hits_needed = 0;
  std::uint32_t camera = 0;  ///< the camera that saw it (the working memory's id of the camera)
};

/// The ids of pending changes, one space for every kind: an id names one candidate, whatever
/// kind, so a request needs no kind beside it. Counts from 1 and is never reset (not even by
/// the filters' reset()), so an id is not reused while its counter lives. Thread safe.
class PendingIds {
 public:
  std::uint64_t next() { return ++last_; }
  /// The largest id given so far (0: none).
  std::uint64_t last() const { return last_.load(); }

 private:
  std::atomic<std::uint64_t> last_{0};
};

}  // namespace scenewatch::change
