#pragma once
/// The segmented objects of one frame by point, for whole-object completion (whole_objects.h).
#include <vector>

#include "scenewatch/change/mismatch.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::change {

/// Which segmented object each point of a frame belongs to, and each object's points.
struct ObjectLabels {
  std::vector<int> object_of;             ///< per point of the cloud: object index, -1 for none
  std::vector<std::vector<int>> members;  ///< per object: its point indices, ascending
};

/// The labels of a segmentation of a cloud of `cloud_size` points.
ObjectLabels label_objects(const segmentation::Segmentation& segmentation, std::size_t cloud_size);

/// Segments a frame (in its camera frame) and labels its points. An organized cloud is segmented
/// on every `stride_px`-th pixel of every `stride_px`-th row (min_cluster_points scaled down to
/// the same surface); each point then takes the object of the nearest of the samples around its
/// pixel, when that sample lies within one segmentation voxel of it. Unorganized clouds, and
/// stride_px 1, are segmented whole.
ObjectLabels segment_objects(const Cloud& cloud_camera, const segmentation::Config& config, int stride_px);

/// Joins the pieces of one object that a nearer one splits (a lying tin behind a standing box):
/// two objects of an organized cloud whose pixels, along the line between their pixel centroids,
/// are separated by a stretch that shows a surface in front of both (by more than the tolerance
/// at its depth, `config`; pixels without depth aside, so long as they are fewer). Unorganized
/// clouds are left as they are.
void join_hidden_pieces(ObjectLabels& labels, const Cloud& cloud_camera, const Config& config);

}  // namespace scenewatch::change
