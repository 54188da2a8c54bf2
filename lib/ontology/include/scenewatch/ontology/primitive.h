#pragma once
/// Geometric primitives fitted to the points of one object, in the frame of its cloud.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace scenewatch::ontology {

enum class PrimitiveKind { kPlane, kCylinder, kSphere, kCone };

/// "plane", "cylinder", "sphere", "cone".
const char* to_string(PrimitiveKind kind);

/// One shape found by the shape detection, with the points it explains.
struct Primitive {
  PrimitiveKind kind = PrimitiveKind::kPlane;
  /// Plane: a point on it; cylinder: a point on the axis; sphere: the centre; cone: the apex.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// Plane: the unit normal; cylinder and cone: the unit axis (cone: from the apex into the
  /// cone); sphere: unused (zero).
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double radius_m = 0.0;      ///< cylinder and sphere
  double half_angle_deg = 0.0;  ///< cone
  std::vector<int> indices;   ///< the points it explains, indices into the input cloud
  double rms_m = 0.0;         ///< root mean square point-to-surface distance of those points
};

/// Unsigned distance of p to the surface of a primitive (cone: to the nappe the axis points into).
double distance_to_surface(const Primitive& primitive, const Eigen::Vector3d& p);

/// A cylinder refined on a partial view: what a camera sees of a can is about half of it.
struct CylinderFit {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< on the axis, at mid height of the inliers
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   ///< unit; sign: towards the sensor side's up when known
  double radius_m = 0.0;
  double height_m = 0.0;      ///< extent of the inliers along the axis
  double rms_m = 0.0;         ///< root mean square radial residual of the inliers
  double coverage_deg = 0.0;  ///< angular extent of the seen arc about the axis (360 - largest gap)
  std::size_t inliers = 0;
  bool axis_fixed = false;    ///< true: the axis was held to the upright prior, not fitted
  /// true: started from a cylinder (or straight cone) of the shape detection; false: from the
  /// upright circle fit, tried on every object without one (a box gets a poor cylinder this way:
  /// judge it by rms_m and coverage_deg)
  bool from_detection = true;
  int iterations = 0;         ///< Levenberg-Marquardt iterations, summed over the rounds
  std::vector<int> indices;   ///< the inliers, indices into the input cloud
};

}  // namespace scenewatch::ontology
