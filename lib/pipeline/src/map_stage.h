#pragma once
// The background map's part of a frame: geometric change detection against the map as it stands
// before the frame, then the frame into the map (without the points of unconfirmed candidates),
// and the confirmed changes written into it. Owns the map, the surface witness and the persistence
// filter. Thread safe as the working memory uses it: update() and the writers run under its
// writer lock; read() takes the map's shared lock and may run beside update()'s change detection.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/change/dark_space.h"
#include "scenewatch/change/mismatch.h"
#include "scenewatch/change/persistence.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/pipeline/config.h"
#include "scenewatch/pipeline/frame_result.h"

namespace scenewatch::pipeline {

/// What geometric change detection made of one frame.
struct ChangeOutcome {
  std::vector<change::ChangeCluster> pending;   ///< unconfirmed candidates seen in this frame
  std::vector<change::ChangeCluster> absorbed;  ///< more of changes already confirmed
  std::vector<change::ObjectChange> confirmed;  ///< confirmed by this frame
  Intrinsics K;                                 ///< the camera the frame was compared with
};

class MapStage {
 public:
  /// `pending_ids`: where the change candidates' ids come from (shared with the event fusion).
  MapStage(const Config& config, std::shared_ptr<change::PendingIds> pending_ids);

  /// Change detection (when `detect`) against the map as it stands before this frame, then the
  /// frame into the map; fills the result's change and insertion figures. Runs beside the
  /// segmentation and the image surprise, which do not read the map. `record_dark`: the frame's
  /// pixels without depth are the sensor's own (nothing was blanked out of it, as a person is),
  /// and go into the dark space (change/dark_space.h).
  ChangeOutcome update(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                       bool detect, FrameResult& result, std::uint32_t camera, bool record_dark = true);

  /// Records the surfaces of the frame update() last took in the surface witness (which cameras
  /// saw each surface) and its pixels without depth in the dark space, and forgets the surfaces
  /// of the removals it confirmed in both. update() leaves this to whichever of the frame's
  /// threads is free first: the first call does it, a call during it waits for it, later calls
  /// do nothing. Before the next update() or prefill().
  void witness_frame();

  /// Fills the change detection's dense copy of the map around `frame` (placed with T) now, on
  /// the calling thread: the thread that will run update() calls it first, while the frame's other
  /// thread does the work before update() (the hands). update() uses the copy when its box holds
  /// the box of the frame update() is given (the hands' pixels blanked out of that frame can only
  /// shrink it); otherwise it fills the copy again.
  void prefill(const Frame& frame, const Pose& T, const change::Config& config);
  /// Forgets a copy prefill() filled for a frame that never reached update() (its camera was
  /// lost): the map may change before the next frame (ClearBox), and the copy would not.
  void drop_prefill() { prefilled_.reset(); }

  /// The share of world points on surfaces the map remembers (occupied, within the change
  /// detector's tolerance along the ray from `camera`), for the foreground. The tolerance holds,
  /// as the change detector's does, how far the misalignment the detector last measured for this
  /// camera (change::PoseAgreement) moves each point: given poses that disagree with the map by a
  /// few centimetres would otherwise make remembered furniture look new.
  std::function<double(const std::vector<Eigen::Vector3d>&, const Eigen::Vector3d& camera)> occupied_fraction(
      const change::Config& change_config, std::uint32_t camera_id);

  /// `fn(map)` under the map's shared lock.
  template <typename F>
  auto read(F&& fn) const {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    return fn(static_cast<const background::OccupancyMap&>(map_));
  }
  /// `fn(map)` under the map's exclusive lock.
  template <typename F>
  auto write(F&& fn) {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    return fn(map_);
  }

  /// The change candidates not yet confirmed. For the writer only, between frames (the filter
  /// is not guarded).
  std::vector<change::PendingChange> pending() const { return changes_.pending(); }

  /// Forgets what is kept of a camera that is no longer followed.
  void forget_camera(std::uint32_t camera) {
    changes_.forget_camera(camera);
    std::lock_guard<std::mutex> lock(pose_mutex_);
    last_pose_.erase(camera);
  }
  /// An empty map; no candidates.
  void reset();
  /// A loaded map in place of this one (its surfaces seen by no camera of this session); no candidates.
  void replace(background::OccupancyMap map);

 private:
  // With `dark_depth` (and change.see_through_dark), sets it to the depth image the comparison
  // read, for the dark space.
  ChangeOutcome detect_changes(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K,
                               const change::Config& config, std::uint32_t camera,
                               std::shared_ptr<const change::DepthView>* dark_depth);

  // Guards `map_` between writers and concurrent occupancy readers. `witness_` and `dark_` are read
  // by the change detection and written by witness_frame(), one after the other within a frame.
  mutable std::shared_mutex mutex_;
  background::OccupancyMap map_;
  background::DenseGrid map_grid_;  // the change detector's dense copy of the map, its buffers kept between frames
  std::optional<bool> prefilled_;   // prefill()'s fill of map_grid_ since the last update(): true when it succeeded
  Pose prefill_T_ = Pose::Identity();  // the pose prefill() filled map_grid_ at
  std::size_t prefill_points_ = 0;     // the size of the cloud it filled for
  change::SurfaceWitness witness_;  // which cameras saw each surface of the map (written by witness_frame())
  change::DarkSpace dark_;          // space rays without a return crossed (written by witness_frame())
  struct WitnessJob {
    CloudConstPtr cloud;  // the points update() inserted
    Pose T;
    std::uint32_t camera = 0;
    int stride = 1;
    bool record = false;                               // change.witness_per_camera
    std::vector<std::vector<Eigen::Vector3d>> forget;  // the surfaces of confirmed removals
    // The frame's depth as the change detection read it, recorded in the dark space against
    // map_grid_ (null: not recorded); the configuration update() was given, alive until the job is done.
    std::shared_ptr<const change::DepthView> dark_depth;
    const change::Config* change_config = nullptr;
  };
  std::mutex witness_mutex_;                // witness_job_, and witness_ and dark_ while a job runs
  std::optional<WitnessJob> witness_job_;   // the last update()'s, until witness_frame() takes it
  change::PersistenceFilter changes_;  // owned by the writer
  // The pose agreement the change detector last measured, per camera.
  mutable std::mutex pose_mutex_;
  std::map<std::uint32_t, change::PoseAgreement> last_pose_;
};

}  // namespace scenewatch::pipeline
