#pragma once
// Segmenting an unorganized cloud of one view through the image it was taken as
// (core/image_grid.h): the organized path (concave cuts over oriented patches, the occlusion join,
// containers) runs on the recovered image, and its pixels go back to the cloud's points.
#include "scenewatch/core/image_grid.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::segmentation {

/// `image_seg` is the segmentation of organized_cloud(cloud, grid): its indices are pixels. Each
/// point of `cloud` joins the plane or object of its pixel when it is the point that stands for
/// that pixel or lies within `tolerance_m` of it (on an inexact grid a pixel may hold several);
/// index lists come out sorted, counts follow them. Boxes, centroids and colours stay those of
/// the standing points.
Segmentation to_cloud_indices(const Cloud& cloud, const ImageGrid& grid, Segmentation image_seg, double tolerance_m);

}  // namespace scenewatch::segmentation
