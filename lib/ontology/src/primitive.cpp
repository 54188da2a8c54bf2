#include "scenewatch/ontology/primitive.h"

#include <cmath>

#include <Eigen/Geometry>

namespace scenewatch::ontology {

const char* to_string(PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::kPlane: return "plane";
    case PrimitiveKind::kCylinder: return "cylinder";
    case PrimitiveKind::kSphere: return "sphere";
    case PrimitiveKind::kCone: return "cone";
  }
  return "unknown";
}

double distance_to_surface(const Primitive& primitive, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - primitive.point;
  switch (primitive.kind) {
    case PrimitiveKind::kPlane: return std::abs(d.dot(primitive.direction));
    case PrimitiveKind::kCylinder:
      return std::abs((d - d.dot(primitive.direction) * primitive.direction).norm() - primitive.radius_m);
    case PrimitiveKind::kSphere: return std::abs(d.norm() - primitive.radius_m);
    case PrimitiveKind::kCone: {
      // In the plane through the axis and p: the nappe is the line at half_angle from the axis.
      const double along = d.dot(primitive.direction);
      const double across = (d - along * primitive.direction).norm();
      const double angle = primitive.half_angle_deg * M_PI / 180.0;
      return std::abs(across * std::cos(angle) - along * std::sin(angle));
    }
  }
  return std::abs(d.norm());
}

}  // namespace scenewatch::ontology
