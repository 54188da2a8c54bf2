#pragma once
// One fact, one event. Each frame brings image-surprise regions (APPEARANCE_CHANGE candidates)
// and the geometric change detector's pending and confirmed changes. This stage decides what the
// stream says:
// - a surprise region where geometry is changing (a pending or confirmed geometric change, grown by
//   a margin) is evidence for that change, not an event of its own; when the geometric change
//   fires, it carries the strongest such evidence (appearance_kl_mean, appearance_area_px);
// - any other surprise region must persist: it fires as APPEARANCE_CHANGE once it was seen in
//   `persistence_frames` frames at the same place in the world (within `match_m`). Misalignment,
//   specular highlights and sensor noise move with the camera or come and go; a real change of
//   appearance (the seed's removed glasses) stays where it is;
// - a geometric change speaks of whole objects: the evidence of a removal is only the part of the
//   surface that left free space, so a removal (or the old place of a move) takes the box and id
//   of the listed object there, and an addition (or the new place) the box and points of this
//   frame's segmented object there;
// - where an event fired, the same kind of fact is not reported again (a zone, for `zone_frames`):
//   a removal confirmed later inside the place of an earlier removal (or move) is another piece of
//   the same object, seen from a new side; likewise for additions; no appearance-only change is
//   reported where any event fired.
// Each event carries the ids of the pending changes it confirmed (Event::pending_ids): the
// geometric candidates' (from the persistence filter), and its own appearance candidates'.
#include <cstdint>
#include <memory>
#include <vector>

#include "scenewatch/change/objects.h"
#include "scenewatch/change/pending_change.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::pipeline {

struct FusionConfig {
  int persistence_frames = 5;  ///< sightings before an appearance-only change fires
  double match_m = 0.05;       ///< a region matches a candidate within this centroid distance
  double margin_m = 0.05;      ///< geometric boxes are grown by this much to claim regions
  int zone_frames = 300;       ///< a fired event silences its place for this many frames
};

/// NOT thread safe: owned by the working memory's writer. The appearance candidates' ids come
/// from `ids`, the space the persistence filter's candidates share (so one id names one change).
class EventFusion {
 public:
  explicit EventFusion(const FusionConfig& config = {},
                       std::shared_ptr<change::PendingIds> ids = std::make_shared<change::PendingIds>())
      : config_(config), ids_(std::move(ids)) {}

  /// One frame: `appearance` holds this frame's surprise regions as events, `pending` the
  /// geometric candidates seen in this frame, `geometric` the geometric events confirmed by it and
  /// `geometric_boxes` every box they involve (both places of a move). `familiar_view` says
  /// whether the memory knows this view well enough to judge appearance alone (see
  /// AppearanceStage): in a view seen for the first time, surprise regions are only evidence.
  /// Returns the frame's events: the geometric ones (with appearance evidence merged in), then
  /// the appearance-only changes that became persistent.
  /// `objects` is the object list before this frame, `clusters` this frame's segmented objects
  /// (world frame, with their indices in the frame). `camera` names the frame's camera: an
  /// appearance candidate persists, or misses, only in frames of the camera that saw it.
  std::vector<Event> update(const std::vector<Event>& appearance, const std::vector<change::ChangeCluster>& pending,
                            std::vector<Event> geometric, std::vector<Aabb> geometric_boxes, bool familiar_view,
                            const std::vector<TrackedObject>& objects = {},
                            const std::vector<ObjectCluster>& clusters = {}, std::uint32_t camera = 0);
  /// Drops the candidates of a camera that is no longer followed.
  void forget_camera(std::uint32_t camera);

  std::size_t candidates() const { return candidates_.size(); }
  /// The appearance-only candidates not yet persistent (kind kAppearance), oldest first.
  std::vector<change::PendingChange> pending() const;
  void reset();

 private:
  struct Candidate {
    std::uint64_t id = 0;  ///< from ids_, kept while the region is matched
    Event latest;
    int hits = 0;
    int misses = 0;
    double best_kl = 0.0;
    std::uint32_t camera = 0;
  };
  struct Claimed {  ///< appearance evidence gathered for a pending geometric change
    Aabb box;
    double kl = 0.0, area_px = 0.0;
    int age = 0;
  };
  enum class ZoneKind { kAppearance, kRemoved, kAdded };
  struct Zone {
    Aabb box;
    ZoneKind kind;
    int age = 0;
  };
  // The steps of update(), in order.
  void age();
  std::vector<Event> drop_told_pieces(std::vector<Event> geometric) const;
  std::vector<const Event*> claim_appearance(const std::vector<Event>& appearance,
                                             const std::vector<change::ChangeCluster>& pending,
                                             const std::vector<Aabb>& geometric_boxes);
  void tell(Event& e, const std::vector<Aabb>& geometric_boxes);
  void follow_appearance(const std::vector<const Event*>& free_regions, std::uint32_t camera, std::vector<Event>& out);

  FusionConfig config_;
  std::shared_ptr<change::PendingIds> ids_;
  std::vector<Candidate> candidates_;
  std::vector<Claimed> claimed_;
  std::vector<Zone> zones_;
};

}  // namespace scenewatch::pipeline
