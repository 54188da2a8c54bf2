#pragma once
/// The foreground of the working memory (issue 12, seed section 3.3): only what a human hand
/// touches and then moves becomes a mission-relevant object; everything else stays background.
///
/// Per frame, in two steps around the segmentation:
///  1. track(): each touched or foreground object is registered in the frame from its last pose
///     (colour-aware ICP of its point model); the pixels of the foreground objects are returned,
///     so that they stay out of the background map, the change detection and the segmentation
///     (a carried cup is not a change of the room; it is the foreground's).
///  2. update(): the hands' contacts with the frame's objects. A background object a hand touches
///     becomes a candidate; once it has moved away from where it stood (and that place is seen
///     empty) it is promoted (OBJECT_PROMOTED) and its old place is handed back to be cleared
///     in the map. Handlings are recorded per object; the first teaches which DoFs are free, a
///     later motion in a frozen DoF raises FROZEN_DOF_MOTION. An object whose track was lost is
///     searched for among the frame's clusters near where it was last seen (a toy dropped into
///     a bin is the same toy).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/foreground/hand_detector.h"
#include "scenewatch/foreground/handling.h"
#include "scenewatch/foreground/registration.h"

namespace scenewatch::foreground {

struct ForegroundConfig {
  bool enabled = true;
  HandConfig hands;
  RegistrationConfig registration;
  DofThresholds dof;                    ///< the noise level of the DoF learning
  double contact_m = 0.03;              ///< a hand this close to an object's points touches it
  double promote_translation_m = 0.02;  ///< a touched object that moved this far (or turned
  double promote_rotation_deg = 20.0;   ///< this much) from where it stood is promoted...
  double vacated_fraction = 0.3;        ///< ...when at least this share of its old place is seen empty
  /// A touched object that rose this far along the support's normal (more than it moved sideways)
  /// left its support: promoted at once. Above the noise of a tracked object at rest (at most
  /// 1.2 mm in the simulator, 2.8 mm on hrt1 while the hand grasps it).
  double promote_lift_m = 0.006;
  int touch_timeout_frames = 20;        ///< a touched object that did not move is forgotten after this many frames without contact
  int release_frames = 4;               ///< frames without contact that end a handling
  double search_radius_m = 0.3;         ///< frame points this close to the predicted centre are registration targets
  double target_voxel_m = 0.005;        ///< registration targets are thinned to one point per voxel
  double model_voxel_m = 0.005;         ///< and so is the model
  std::size_t max_model_points = 4000;
  /// A foreground object's model grows from its registered views (the frame's points of the
  /// object, skin left out, one per model_voxel_m voxel, up to max_model_points) when the
  /// registration's inlier rmse is at most grow_max_rmse_m and it explains at least
  /// grow_min_inlier_fraction of the model's visible side. false: the model of the first view.
  bool grow_model = true;
  double grow_max_rmse_m = 0.005;
  double grow_min_inlier_fraction = 0.8;
  double mask_m = 0.012;                ///< frame points this close to a registered model are the object's
  double reacquire_radius_m = 0.8;      ///< a lost object is searched for among clusters this close to its last place
};

Status validate(const ForegroundConfig& config);

/// One frame as the foreground sees it.
struct FrameView {
  const Cloud* cloud = nullptr;         ///< camera frame, organized
  Pose T_world_camera = Pose::Identity();
  double stamp_s = 0.0;
  std::uint64_t frame_index = 0;
  const HandDetection* hands = nullptr;
  Eigen::Vector3d up_world = Eigen::Vector3d::UnitZ();
  const std::vector<Plane>* planes = nullptr;  ///< world frame, the last frame's supporting planes
  /// The camera (for "is that place seen empty": a promotion needs the frame to see through
  /// where the object stood); null: that test falls back to "no points there".
  const Intrinsics* K = nullptr;
};

/// What step 2 decided.
struct ForegroundUpdate {
  std::vector<Event> events;                           ///< OBJECT_PROMOTED, FROZEN_DOF_MOTION (ids unset)
  std::vector<std::vector<Eigen::Vector3d>> vacated;   ///< world points of promoted objects' old places: free now
  std::vector<std::uint64_t> promoted;                 ///< ids of background objects that became foreground
  std::vector<std::size_t> claimed_clusters;           ///< indices of clusters that are foreground objects
  std::vector<Aabb> quiet_boxes;                       ///< where background changes are the foreground's doing
};

/// NOT thread safe: owned by the working memory's writer.
class ForegroundTracker {
 public:
  explicit ForegroundTracker(ForegroundConfig config);
  ~ForegroundTracker();
  ForegroundTracker(ForegroundTracker&&) noexcept;
  ForegroundTracker& operator=(ForegroundTracker&&) noexcept;

  /// Step 1: registers the touched and foreground objects in the frame; returns the pixels
  /// (indices into the cloud) of the foreground objects.
  std::vector<int> track(const FrameView& frame);

  /// Step 2: `clusters` are the frame's objects (world frame, indices into the cloud) and `known`
  /// the background objects as the tracker lists them (a touched cluster takes its object's id).
  ForegroundUpdate update(const FrameView& frame, const std::vector<ObjectCluster>& clusters,
                          const std::vector<TrackedObject>& known);

  /// The foreground objects (with ForegroundState set), in the order they were promoted.
  std::vector<TrackedObject> objects() const;
  /// Ids of touched objects not yet promoted.
  std::vector<std::uint64_t> candidates() const;

  /// A foreground object's point model (object frame, with colour), for saving.
  CloudConstPtr model(std::uint64_t id) const;
  /// Restores a saved foreground object.
  void restore(const TrackedObject& object, CloudConstPtr model);
  void reset();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::foreground
