#pragma once
/// The views the last NextBestView answer suggested (issue 31), kept for the live view, which
/// draws them as camera frusta beside the map. The request handler writes it, the live view reads
/// it; the daemon hands both the same one. Thread safe.
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"

namespace scenewatch::service {

struct SuggestedView {
  Pose T_world_camera = Pose::Identity();
  double score = 0.0;
};

struct SuggestedViewSet {
  std::vector<SuggestedView> views;  ///< best first
  Aabb target;                       ///< the box the views look at
  std::string measure;
  /// The camera the views were planned for: its field of view, degrees.
  double horizontal_fov_deg = 0.0, vertical_fov_deg = 0.0;
  std::uint64_t answer = 0;  ///< counts the answers recorded; 0: none yet
};

class SuggestedViews {
 public:
  /// Replaces the views with those of a new answer (and counts it).
  void record(SuggestedViewSet set) {
    std::lock_guard<std::mutex> lock(mutex_);
    set.answer = last_.answer + 1;
    last_ = std::move(set);
  }
  SuggestedViewSet last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }

 private:
  mutable std::mutex mutex_;
  SuggestedViewSet last_;
};

}  // namespace scenewatch::service
