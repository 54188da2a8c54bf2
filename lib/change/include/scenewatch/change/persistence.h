#pragma once
/// The persistence filter of sequences: a candidate change fires only after it was re-observed in
/// `persistence_frames` consistent frames, so depth noise that comes and goes raises nothing.
#include <cstdint>
#include <memory>
#include <vector>

#include "scenewatch/change/objects.h"
#include "scenewatch/change/pending_change.h"

namespace scenewatch::change {

/// NOT thread safe: one per stream, owned by its caller. Each candidate has an id from `ids`
/// (shared with other sources of pending changes, or a counter of its own).
class PersistenceFilter {
 public:
  explicit PersistenceFilter(const Config& config, std::shared_ptr<PendingIds> ids = std::make_shared<PendingIds>())
      : config_(config), ids_(std::move(ids)) {}

  /// Feeds one frame's clusters. Returns the changes confirmed by this frame (moves paired), each
  /// with the ids of the candidates it confirmed (ObjectChange::pending_ids).
  /// `pending` receives the clusters of this frame that belong to unconfirmed candidates: their
  /// pixels should be kept out of the model until confirmed. `absorbed` receives clusters that
  /// lie where a change of their kind was already confirmed (the other sides of an object that
  /// was added or taken away, seen from new views): the caller writes them into the model
  /// without a new event.
  /// `camera` names the camera of the frame: a candidate is matched, and counted missing, only in
  /// frames of the camera that saw it (another camera looking elsewhere is no evidence against it).
  std::vector<ObjectChange> update(const std::vector<ChangeCluster>& clusters, std::vector<ChangeCluster>* pending,
                                   std::vector<ChangeCluster>* absorbed = nullptr, std::uint32_t camera = 0);
  /// Drops the candidates of a camera that is no longer followed.
  void forget_camera(std::uint32_t camera);

  std::size_t candidates() const { return candidates_.size(); }
  /// The unconfirmed candidates after the last update(), oldest first: what a planner may look at
  /// to confirm or dismiss. A candidate keeps its id while it is matched; once confirmed or
  /// dropped it is gone from the list, and its id is never listed again.
  std::vector<PendingChange> pending() const;
  void reset() {
    candidates_.clear();
    zones_.clear();
  }

 private:
  struct Candidate {
    std::uint64_t id = 0;  ///< from ids_, kept across the frames it is matched in
    ChangeCluster latest;
    int hits = 0;
    int misses = 0;  ///< consecutive frames without a match
    int waited = 0;  ///< frames waited, once confirmed, for a move partner
    std::uint32_t camera = 0;  ///< the camera that saw it
  };
  struct Zone {
    ChangeKind kind;
    Aabb box_world;  ///< the confirmed change's box, grown by a margin
  };
  // The steps of update(), in order. `matched` and `done` run parallel to candidates_.
  /// Matches each cluster to a candidate of its camera and kind (or starts one; absorbs those in a
  /// zone) and counts a miss for this camera's others. Returns which candidates were matched.
  std::vector<char> match(const std::vector<ChangeCluster>& clusters, std::vector<ChangeCluster>* absorbed,
                          std::uint32_t camera);
  /// Drops the candidates missed persistence_frames times in a row, and their `matched` entries.
  void drop_missing(std::vector<char>& matched);
  bool ready(const Candidate& c) const;
  /// The moves among the ready candidates, most similar pairs first; marks their halves done.
  std::vector<ObjectChange> pair_moves(std::vector<char>& done) const;
  /// Whether an unready candidate of the other kind could still pair with candidate i.
  bool partner_coming(std::size_t i, const std::vector<char>& done) const;
  /// Appends the ready candidates that fire alone to `out` (or absorbs them as parts of one that did).
  void fire_singles(std::vector<char>& done, std::vector<ObjectChange>& out, std::vector<ChangeCluster>* absorbed);
  /// Keeps the boxes of the changes that fired as zones (bounded).
  void remember_zones(const std::vector<ObjectChange>& fired);
  /// Drops the candidates that fired; reports this frame's matched rest as pending.
  void keep_unfired(const std::vector<char>& done, const std::vector<char>& matched, std::vector<ChangeCluster>* pending);

  Config config_;
  std::shared_ptr<PendingIds> ids_;
  std::vector<Candidate> candidates_;
  std::vector<Zone> zones_;  ///< confirmed changes, most recent last (bounded)
};

}  // namespace scenewatch::change
