#pragma once
/// Large planes in a camera-frame point grid: near-horizontal ones (table, floor) and, optionally,
/// any large plane (a wall): where neither a hand nor a person can be. Private to the foreground
/// module.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace scenewatch::foreground {

/// A plane n.p + d = 0 in the camera frame, n unit, oriented towards the camera (d > 0).
struct SupportPlane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitY();
  float d = 0.0f;
  std::size_t inliers = 0;
  float distance(const Eigen::Vector3f& p) const { return normal.dot(p) + d; }
};

struct SupportPlaneConfig {
  float tolerance_m = 0.015f;     ///< a point this close to the plane lies on it (up to 1.5 m depth)
  /// Beyond 1.5 m the tolerance grows with depth squared, as the depth error of structured-light
  /// and stereo sensors does (Khoshelham & Elberink 2012, Sensors 12(2), eq. 17).
  float tolerance_at(float z) const { return tolerance_m * std::max(1.0f, (z / 1.5f) * (z / 1.5f)); }
  float min_abs_normal_y = 0.7f;  ///< the normal within ~45 degrees of the image's vertical axis; 0: any plane
  double min_fraction = 0.05;     ///< of the valid points, for the plane to count as large
  double min_patch_fraction = 0.005;  ///< a connected patch of inliers smaller than this is not the plane
  /// A plane through (or near) the camera's centre projects to a line in the image, and every
  /// pixel on that line is its inlier whatever its depth: such planes are not surfaces.
  float min_camera_distance_m = 0.3f;
  /// A patch must be a surface, not where the plane cuts another surface (a thin band across a
  /// wall, an arm): the second principal spread of its points, at least this.
  float min_patch_width_m = 0.08f;
  int max_planes = 2;             ///< table and floor
  int iterations = 300;
};

/// Finds up to max_planes large planes (normal.y at least min_abs_normal_y) among the points of a
/// width x height grid with valid[i] != 0, the largest first, and sets on_plane[i] = 1 for the
/// points that lie on one. A plane is its large connected patches of inliers, not the infinite
/// plane: where a table's plane cuts through an arm or a wall is not the table. Deterministic
/// (fixed seed). "Near-horizontal" assumes the image is not rolled by more than about 45 degrees.
std::vector<SupportPlane> find_support_planes(const std::vector<Eigen::Vector3f>& points,
                                              const std::vector<std::uint8_t>& valid, int width, int height,
                                              const SupportPlaneConfig& config, std::vector<std::uint8_t>* on_plane);

/// The fewest points on a plane for it to count as large, of `valid_points` valid ones.
std::size_t min_plane_inliers(const SupportPlaneConfig& config, std::size_t valid_points);

/// Of a plane's `inliers` (grid indices), the large and wide connected patches: sets on_plane[i] = 1
/// for their points and returns how many they are, or 0 (and sets nothing) when fewer than
/// `min_inliers`. `total`: the valid points of the grid, which min_patch_fraction is of.
std::size_t keep_large_patches(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& inliers, int width,
                               int height, const SupportPlaneConfig& config, std::size_t total, std::size_t min_inliers,
                               std::vector<std::uint8_t>* on_plane);

}  // namespace scenewatch::foreground
