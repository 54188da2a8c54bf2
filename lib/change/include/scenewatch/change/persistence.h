#pragma once
/// The persistence filter of sequences: a candidate change fires only after it was re-observed in
/// `persistence_frames` consistent frames, so depth noise that comes and goes raises nothing.
#include <cstdint>
#include <vector>

#include "scenewatch/change/objects.h"

namespace scenewatch::change {

/// NOT thread safe: one per stream, owned by its caller.
class PersistenceFilter {
 public:
  explicit PersistenceFilter(const Config& config) : config_(config) {}

  /// Feeds one frame's clusters. Returns the changes confirmed by this frame (moves paired).
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
  void reset() {
    candidates_.clear();
    zones_.clear();
  }

 private:
  struct Candidate {
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
  Config config_;
  std::vector<Candidate> candidates_;
  std::vector<Zone> zones_;  ///< confirmed changes, most recent last (bounded)
};

}  // namespace scenewatch::change
