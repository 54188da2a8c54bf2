#pragma once
/// What segmentation finds and what the working memory keeps: planes and objects.
#include <cstdint>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"

namespace scenewatch {

/// A supporting plane: n . x + d = 0 with n pointing towards the sensor side (where objects
/// stand), and its convex hull polygon, all in the frame of the cloud it was found in.
struct Plane {
  int id = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  std::vector<Eigen::Vector3d> hull;  ///< convex polygon on the plane, counter-clockwise about n
  double area_m2 = 0.0;
  std::size_t inlier_count = 0;       ///< input points on the plane
  std::vector<int> indices;           ///< indices of the inliers in the input cloud
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double signed_distance(const Eigen::Vector3d& p) const { return normal.dot(p) + d; }
};

/// A cluster of points standing on a plane.
struct ObjectCluster {
  int plane_id = 0;
  /// What the object stands on: -1 for its plane, else the index of the object under it in the
  /// same segmentation (a box on a box).
  int supported_by = -1;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  OrientedBox box;                    ///< z axis along the plane normal, yaw from the points
  std::size_t point_count = 0;
  std::vector<int> indices;           ///< indices in the input cloud
  Eigen::Vector3f mean_rgb = Eigen::Vector3f::Zero();  ///< 0..255
};

/// An object the working memory keeps track of across frames (cluster level for now).
struct TrackedObject {
  std::uint64_t id = 0;
  ObjectCluster cluster;              ///< last observation, in world coordinates
  double first_seen_s = 0.0;
  double last_seen_s = 0.0;
  int observations = 0;
  /// Id of the object it stands on (a box on a box); 0: it stands on its plane.
  std::uint64_t supported_by = 0;
};

}  // namespace scenewatch
