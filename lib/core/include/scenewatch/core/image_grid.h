#pragma once
/// The image behind an unorganized cloud of one view. A depth camera's cloud loses its image grid
/// when invalid points are dropped (pcl::removeNaNFromPointCloud, most converters and bag tools)
/// or when the points are reordered; every neighbourhood the image gave (depth edges, occlusion,
/// pixel adjacency) is lost with it. When all points were seen from one sensor, the grid comes
/// back by projecting each point along its ray:
///  - exactly, when the rays fall on a pixel lattice (the cloud is a depth image's pixels): the
///    focal length is the lattice's spacing, the principal point its offset;
///  - otherwise, onto a virtual pinhole whose pixels are as fine as the points' angular spacing,
///    the nearest point of a pixel standing for it.
/// A cloud merged from several views is not one image: too many of its points hide behind others
/// along their rays. It gets no grid.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch {

struct ImageGrid {
  Intrinsics K;
  /// True when the rays fall on a pixel lattice (within a tenth of a pixel), so each pixel holds
  /// at most one point, as in the image the cloud was made from.
  bool exact = false;
  /// Per input point: its pixel (v * width + u), -1 for invalid points and points behind the sensor.
  std::vector<int> pixel;
  /// Per pixel: the input point that stands for it (the nearest), -1 for none.
  std::vector<int> point;
};

struct ImageGridParams {
  /// Share of points that may lie hidden behind a nearer point of their own pixel (farther than
  /// hidden_gap_m + 5 % of its range) before the cloud counts as merged from several views.
  double max_hidden_share = 0.05;
  double hidden_gap_m = 0.02;
  /// The largest image made (pixels per side).
  int max_side = 4096;
};

/// The image grid of an unorganized cloud seen from `sensor_origin`, looking along +z of
/// `sensor_orientation` (PCD's VIEWPOINT; identity: the cloud is in the camera frame), or nothing
/// when it is not one view (fewer than 100 points, a point in a thousand or more behind the
/// sensor, or too many hidden, see above) or already organized.
std::optional<ImageGrid> recover_image_grid(const Cloud& cloud, const Eigen::Vector3d& sensor_origin,
                                            const Eigen::Quaternionf& sensor_orientation = Eigen::Quaternionf::Identity(),
                                            const ImageGridParams& params = {});

/// The organized cloud of a grid: each pixel holds the point that stands for it, NaN elsewhere.
Cloud organized_cloud(const Cloud& cloud, const ImageGrid& grid);

}  // namespace scenewatch
