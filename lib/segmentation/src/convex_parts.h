#pragma once
// Splitting a cluster of touching objects at its concave boundaries: local convexity over small
// surface patches, after Stein, Schoeler, Papon & Woergoetter, "Object Partitioning using Local
// Convexity", CVPR 2014 (PCL's LCCPSegmentation). Two objects pressed together or stacked meet
// in a concave crease (the side of the upper box rises from the top of the lower one); the
// surfaces of one object meet in convex edges or continue smoothly.
//
// Patches are the cells of a voxel grid over the cluster's points (VCCS supervoxels refine such
// cells by flow; plain cells are cheaper and work the same on organized and unorganized clouds).
#include <Eigen/Core>

#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

struct ConvexityParams {
  double patch_size_m = 0.02;
  double concavity_tolerance_deg = 20.0;
  /// Concave links flatter than this count as one object's curvature when surfaces vote.
  double crease_angle_deg = 45.0;
  /// Parallel patches offset along their normal by more than this share of their distance are a
  /// step (one surface in front of another), not one surface.
  double max_step_ratio = 0.5;
  /// Parts narrower than this (across their second principal axis) are fragments (a row of
  /// patches straddling a crease) and are shared out among the parts they touch.
  double min_part_size_m = 0.03;
};

/// The convex parts of one cluster (indices into `cloud`), each a sorted index list. The sensor
/// at `sensor_origin` orients the patch normals. One part when nothing is concave.
std::vector<std::vector<int>> split_at_concavities(const Cloud& cloud, const std::vector<int>& cluster,
                                                   const Eigen::Vector3d& sensor_origin, const ConvexityParams& params);

}  // namespace scenewatch::segmentation
