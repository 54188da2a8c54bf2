#pragma once
/// Where the hands are in a frame, in the world, for "does a hand touch this": the hand proper's
/// points (the forearm touches nothing it carries) within contact_m. Private to the foreground
/// module.
#include <vector>

#include "scenewatch/foreground/foreground_tracker.h"
#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {

/// A touched cluster larger than this is furniture, not an object.
constexpr double kMaxObjectExtentM = 0.6;

/// The hands of one frame. Immutable once made.
class HandContact {
 public:
  /// From f.hands (the tip pixels of each hand, or all of its pixels when it has none).
  HandContact(const FrameView& f, double contact_m);
  /// True when the frame has a hand point.
  bool any() const { return any_hand_; }
  /// False when the cluster's box lies too far from every hand for any of its points to touch one.
  bool may_touch(const ObjectCluster& c) const;
  /// True when one of the points (world frame) lies within contact_m of a hand point.
  bool touches(const std::vector<Eigen::Vector3d>& pts) const;

 private:
  VoxelSet hand_;  ///< the hand points' voxels grown by one: one lookup per point
  Aabb reach_;
  bool any_hand_ = false;
};

}  // namespace scenewatch::foreground
