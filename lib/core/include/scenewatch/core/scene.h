#pragma once
/// What segmentation finds and what the working memory keeps: planes and objects.
#include <cstdint>
#include <string>
#include <optional>
#include <vector>

#include "scenewatch/core/dof.h"
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
  /// Its unit normal turned towards the side `p` is on (a table's up, seen from a camera above it).
  Eigen::Vector3d normal_towards(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d n = normal.normalized();
    return n.dot(p - centroid) >= 0 ? n : Eigen::Vector3d(-n);
  }
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
  /// The points' colour covariance (0..255 units squared): how much the object's colours vary,
  /// which the expected view assumes for a side of the object it has not seen.
  Eigen::Matrix3f rgb_covariance = Eigen::Matrix3f::Zero();
};

/// One episode of a person handling a foreground object, from the first touch to the release.
struct Handling {
  double start_s = 0.0;
  double end_s = 0.0;      ///< 0 while it goes on
  DofVector range{};       ///< max - min per DoF over the episode (m, degrees), in the support frame
  DofFlags moved{};        ///< range above the noise level
};

/// What the foreground knows of an object a hand touched and moved (issue 12).
struct ForegroundState {
  Pose T_world_object = Pose::Identity();  ///< its model's frame (origin at its centroid when promoted)
  DofFlags free{};                         ///< false: frozen (never seen moving while handled)
  std::vector<Handling> handlings;         ///< oldest first
  bool in_hand = false;
  bool visible = true;                     ///< registered in the last frame
  double promoted_s = 0.0;
  std::size_t model_points = 0;
};

/// An object the working memory keeps track of across frames.
struct TrackedObject {
  std::uint64_t id = 0;
  ObjectCluster cluster;              ///< last observation, in world coordinates
  double first_seen_s = 0.0;
  double last_seen_s = 0.0;
  int observations = 0;
  /// Id of the object it stands on (a box on a box); 0: it stands on its plane.
  std::uint64_t supported_by = 0;
  std::optional<ForegroundState> foreground;  ///< set once a hand touched and moved it
};

}  // namespace scenewatch
