#pragma once
/// Object-level scoring of change events against ground truth, strict both ways: recall is the
/// share of true changes (whole objects) that some event matches at point IoU >= a threshold
/// (0.5), precision the share of events that match some true change at that IoU (an event that
/// covers only the fringe of an object, or most of it plus much else, is wrong); IoU is the best
/// event's, averaged over the matched changes. (Until the calm-stream work the precision was
/// by majority of points and the recall at IoU 0.3, after Dynablox, Schmid et al. 2023: lenient.)
#include <cstdint>
#include <vector>

#include "scenewatch/core/event.h"

namespace scenewatch::change {

/// A true change: its points in BEFORE (removed, moved) and/or AFTER (added, moved).
struct TrueChange {
  std::uint32_t object_id = 0;
  std::vector<int> indices_before, indices_after;
};

struct ChangeScore {
  std::size_t events = 0, true_changes = 0;
  std::size_t matched_events = 0, matched_changes = 0;
  double iou_sum = 0.0;  ///< over matched true changes (best IoU)
  double precision() const { return events ? static_cast<double>(matched_events) / events : 1.0; }
  double recall() const { return true_changes ? static_cast<double>(matched_changes) / true_changes : 1.0; }
  double mean_iou() const { return matched_changes ? iou_sum / matched_changes : 0.0; }
  ChangeScore& operator+=(const ChangeScore& o);
};

/// Point IoU of an event with a true change: the union of its BEFORE and AFTER points against the
/// change's, each side in its own index space.
double change_iou(const Event& event, const TrueChange& truth);

/// Scores events against true changes (see above).
ChangeScore score_changes(const std::vector<Event>& events, const std::vector<TrueChange>& truth,
                          double iou_threshold = 0.5);

/// True changes of a same-camera pair from per-point object labels (mOSD: id = label / 10,
/// labels below `min_label` are background), read pixel by pixel (the scenes are organized and
/// the camera did not move). An object's pixels are read in the other scene: hidden where that
/// scene has a surface more than `near_m` in front, kept where its depth is within `near_m`,
/// changed otherwise. An object of AFTER is added, or one of BEFORE removed, when fewer than
/// `kept_fraction` of its seen (not hidden) pixels are kept; so a move of 2 cm or a turn in place
/// is a removal plus an addition, as the diff's OBJECT_MOVED should be. An object mostly hidden
/// in the other scene is left out (occluded: unknown, not a change), as are objects with fewer
/// than min_points labelled points.
///
/// `near_m` of 1 cm is 7x the Kinect's depth noise at 0.7 m (about 1.4 mm, Khoshelham and Oude
/// Elberink 2012), so an unmoved surface keeps all but its flickering edge pixels; a rigid motion
/// of 2 cm moves the depth of every face not parallel to it and uncovers a strip at each side.
std::vector<TrueChange> true_changes_from_labels(const std::vector<Eigen::Vector3f>& before_xyz,
                                                 const std::vector<std::uint32_t>& before_labels,
                                                 const std::vector<Eigen::Vector3f>& after_xyz,
                                                 const std::vector<std::uint32_t>& after_labels,
                                                 std::uint32_t divisor = 10, std::uint32_t min_label = 10,
                                                 double near_m = 0.01, std::size_t min_points = 100,
                                                 double kept_fraction = 0.8);

/// True when two labelled organized scenes come from one unmoved camera: most pixels both label
/// as the support (`table_label`) have the same depth (to 0.1 mm; mOSD's sessions share the
/// table's exact depth).
bool same_camera_by_labels(const std::vector<Eigen::Vector3f>& before_xyz, const std::vector<std::uint32_t>& before_labels,
                           const std::vector<Eigen::Vector3f>& after_xyz, const std::vector<std::uint32_t>& after_labels,
                           std::uint32_t table_label = 1);

}  // namespace scenewatch::change
