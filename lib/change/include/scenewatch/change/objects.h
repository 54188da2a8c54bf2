#pragma once
/// From mismatch pixels and voxels to object-level changes: connected clusters with a metric size
/// filter, then vanished/appeared pairs of similar shape and colour as moves.
#include <array>
#include <cstdint>
#include <vector>

#include "scenewatch/change/mismatch.h"
#include "scenewatch/core/event.h"

namespace scenewatch::change {

enum class ChangeKind { kAdded, kRemoved };

/// One connected group of mismatch evidence.
struct ChangeCluster {
  ChangeKind kind = ChangeKind::kAdded;
  /// Added: indices into the observation. Removed: indices into the earlier observation when it
  /// is known (diffs), else empty.
  std::vector<int> indices;
  std::vector<Eigen::Vector3d> points_world;  ///< the evidence: points (added) or voxel centres (removed)
  Aabb box_world;
  Eigen::Vector3d centroid_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_rgb = Eigen::Vector3d::Zero();
  PixelRegion region;            ///< in the observation
  double mean_gap_m = 0.0;       ///< mean depth or surface distance of the evidence
  std::size_t evidence_count = 0;  ///< pieces of mismatch evidence (points or voxels) it grew from
  /// True when `indices` and `points_world` are whole segmented objects of the frame
  /// (whole_objects.h), not the evidence itself.
  bool completed = false;
  /// Sorted box sides, largest first.
  Eigen::Vector3d sorted_extent() const;
};

/// An object-level change: added, removed, or a removed/added pair that is one object moved.
struct ObjectChange {
  EventKind kind = EventKind::kObjectAdded;  ///< kObjectAdded, kObjectRemoved or kObjectMoved
  std::optional<ChangeCluster> before;       ///< the vanished side (removed, moved)
  std::optional<ChangeCluster> after;        ///< the appeared side (added, moved)
  double similarity = 0.0;                   ///< moves: 1 = same size and colour
  /// The persistence filter's candidates it confirmed (PendingChange ids); empty from a diff.
  std::vector<std::uint64_t> pending_ids;
};

/// Inputs of clustering besides the mismatch: the observation and, for same-camera pairs or
/// diffs through the map, the earlier observation whose points give the removed side's indices.
struct ClusterInput {
  const Cloud* after_camera = nullptr;
  Pose T_world_after = Pose::Identity();
  Intrinsics K_after;
  const Cloud* before_camera = nullptr;  ///< optional
  Pose T_world_before = Pose::Identity();
};

/// The pixel of point i: its place in the grid of an organized cloud, else its projection with K.
std::array<int, 2> pixel_of(const Cloud& cloud, int i, const Intrinsics& K);

/// Groups the mismatch into clusters and drops those below the size thresholds.
std::vector<ChangeCluster> cluster_mismatch(const Mismatch& mismatch, const ClusterInput& input, const Config& config);

/// Similarity of a vanished and an appeared cluster in [0, 1]; 0 when they cannot be one object.
double move_similarity(const ChangeCluster& removed, const ChangeCluster& added, const Config& config);

/// Pairs removed and added clusters greedily by similarity into moves; the rest stay single.
std::vector<ObjectChange> pair_changes(std::vector<ChangeCluster> clusters, const Config& config);

/// The event of a change (id and stamp left for the caller).
Event to_event(const ObjectChange& change);

}  // namespace scenewatch::change
