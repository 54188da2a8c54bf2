#pragma once
/// Scoring a segmentation against per-point ground-truth labels (mOSD convention: label 1 is the
/// table, objects are 20, 30, ...; parts of one object share the tens digit, id = label / 10).
#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

struct ObjectScore {
  std::uint32_t object_id = 0;  ///< label / divisor
  std::size_t points = 0;       ///< ground-truth points
  double best_iou = 0.0;        ///< best point IoU over all clusters
  int best_cluster = -1;
};

/// Strict both ways, at point IoU >= a threshold against whole labelled objects: recall is the
/// share of labelled objects some reported cluster matches, precision the share of reported
/// clusters that match a labelled object (a piece of an object, a merge of two, or something
/// unlabelled does not).
struct LabelScore {
  std::vector<ObjectScore> objects;
  std::vector<double> cluster_best_iou;  ///< per reported cluster: its best IoU with a labelled object
  double table_iou = 0.0;       ///< IoU of the first plane's indices with label `table_label`
  /// Objects whose best IoU reaches `iou_threshold`.
  std::size_t matched(double iou_threshold = 0.5) const;
  double recall(double iou_threshold = 0.5) const;
  /// Reported clusters whose best IoU reaches `iou_threshold`.
  std::size_t correct_clusters(double iou_threshold = 0.5) const;
  double precision(double iou_threshold = 0.5) const;
};

/// Scores clusters (point indices per cluster) and a plane (its indices) against labels.
/// Objects with fewer than `min_object_points` labelled points are left out (too small to count).
LabelScore score_against_labels(const std::vector<std::vector<int>>& clusters, const std::vector<int>& plane_indices,
                                const std::vector<std::uint32_t>& labels, std::uint32_t table_label = 1,
                                std::uint32_t divisor = 10, std::size_t min_object_points = 0);

/// A cloud with one label per point.
struct LabelledCloud {
  Cloud cloud;
  std::vector<std::uint32_t> labels;
};

/// The valid points of a labelled scene in a seeded random order, with their labels, height 1:
/// the scene as a converter that drops NaNs, or a merge, hands it over.
LabelledCloud unorganized_copy(const Cloud& cloud, const std::vector<std::uint32_t>& labels, std::uint32_t seed);

}  // namespace scenewatch::segmentation
