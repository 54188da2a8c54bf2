#pragma once
// The extent of a supporting plane: the connected part of its inliers on a coarse grid in the
// plane. Seen from one sensor, a pile of objects hides the table under and behind it, so the
// visible table falls into pieces around the pile; the pieces are one support when the table
// continues, hidden, between them. The hidden cells are those each object voxel covers: from its
// foot on the plane to where the ray from the sensor through it meets the plane (its shadow).
// A voxel within the sensor's noise of the plane is the plane itself and hides nothing. What
// stands over a hidden cell rests on the support there: its foot widens the support's hull, and
// it hides the support behind it in turn (a box behind a box behind a pile).
#include <Eigen/Core>

#include <functional>
#include <optional>
#include <vector>

namespace scenewatch::segmentation {

/// A plane n.x + d = 0 with its 2D basis (u, v); n points to where objects stand.
struct PlaneGrid {
  Eigen::Vector3d n, u, v;
  double d = 0.0;
  double cell_m = 0.05;  ///< gaps narrower than a cell do not split the plane
  /// A visible piece other than the largest joins the support only with this many inlier voxels
  /// (a cell's worth): a voxel or two in the plane's band is no piece of a table.
  std::size_t min_piece_voxels = 1;
};

/// The largest 8-connected piece of the inlier voxels (indices into `centroids`) on the plane's
/// grid, and the pieces that cells hidden from `sensor_origin` join to it, when `sensor_origin`
/// is given: hidden by the voxels `standing`, those at a height above the plane in
/// (min_height_m, max_height_m] and above noise_floor_m(their range from the sensor). Hidden
/// cells connect; they are not inliers. `visible_piece`, when given, receives the largest piece
/// alone. `hidden_feet`, when given, receives the feet on the plane of the voxels `standing` (in
/// the same height band) over hidden cells of the support, except cells that something taller
/// than max_height_m stands on: what rests on the support where the sensor cannot see it.
std::vector<int> support_extent(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& inliers,
                                const PlaneGrid& plane, const std::vector<int>& standing,
                                const std::optional<Eigen::Vector3d>& sensor_origin, double min_height_m,
                                double max_height_m, const std::function<double(double range_m)>& noise_floor_m,
                                std::vector<int>* visible_piece = nullptr,
                                std::vector<Eigen::Vector3d>* hidden_feet = nullptr);

}  // namespace scenewatch::segmentation
