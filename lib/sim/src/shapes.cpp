#include "scenewatch/sim/shapes.h"

#include "shape_math.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::sim {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

/// Exact signed distance to a capped cone in (rho, z) coordinates, z from 0 to h, base radius
/// ra, top radius rb (Inigo Quilez's sdCappedCone, shifted to the base).
double capped_cone_sdf(double rho, double z, double h, double ra, double rb) {
  const double hh = 0.5 * h;
  const Vector2d q(rho, z - hh);
  const Vector2d k1(rb, hh);
  const Vector2d k2(rb - ra, 2.0 * hh);
  const Vector2d ca(q.x() - std::min(q.x(), q.y() < 0.0 ? ra : rb), std::abs(q.y()) - hh);
  const double k2k2 = k2.squaredNorm();
  const double f = k2k2 > 0 ? std::clamp((k1 - q).dot(k2) / k2k2, 0.0, 1.0) : 0.0;
  const Vector2d cb = q - k1 + k2 * f;
  const double sign = (cb.x() < 0.0 && ca.y() < 0.0) ? -1.0 : 1.0;
  return sign * std::sqrt(std::min(ca.squaredNorm(), cb.squaredNorm()));
}

}  // namespace

const char* to_string(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kBox: return "box";
    case ShapeKind::kCylinder: return "cylinder";
    case ShapeKind::kFrustum: return "frustum";
    case ShapeKind::kSphere: return "sphere";
    case ShapeKind::kCapsule: return "capsule";
  }
  return "unknown";
}

double Shape::total_height_m() const {
  switch (kind) {
    case ShapeKind::kBox: return size_m.z();
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum: return height_m;
    case ShapeKind::kSphere: return 2.0 * radius_m;
    case ShapeKind::kCapsule: return height_m + 2.0 * radius_m;
  }
  return 0.0;
}

bool intersect(const Shape& shape, const Vector3d& o, const Vector3d& d, double t_min, double t_max,
               ShapeHit* hit) {
  return detail::intersect_inline(shape, o, d, t_min, t_max, hit);
}

double signed_distance(const Shape& shape, const Vector3d& p) {
  switch (shape.kind) {
    case ShapeKind::kBox: {
      const Vector3d half = 0.5 * shape.size_m;
      const Vector3d q = (p - Vector3d(0, 0, half.z())).cwiseAbs() - half;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum: {
      const double rho = std::hypot(p.x(), p.y());
      const double h = shape.height_m;
      const double r0 = shape.radius_m;
      const double r1 = shape.top_radius_or_radius_m();
      const double outer = capped_cone_sdf(rho, p.z(), h, r0, r1);
      if (!shape.open_top) return outer;
      // The cavity: the frustum shrunk by the wall, from the inner bottom to above the rim.
      const double w = shape.wall_m;
      const double s = (r1 - r0) / h;
      const double ra = r0 - w + s * w;
      const double rb = r0 - w + s * (h + w);
      const double cavity = capped_cone_sdf(rho, p.z() - w, h, std::max(ra, 0.0), std::max(rb, 0.0));
      return std::max(outer, -cavity);
    }
    case ShapeKind::kSphere:
      return (p - Vector3d(0, 0, shape.radius_m)).norm() - shape.radius_m;
    case ShapeKind::kCapsule: {
      const double r = shape.radius_m;
      const double z = std::clamp(p.z(), r, r + shape.height_m);
      return (p - Vector3d(0, 0, z)).norm() - r;
    }
  }
  return 0.0;
}

void bounding_box(const Shape& shape, Vector3d* lo, Vector3d* hi) {
  double r = 0.0;
  switch (shape.kind) {
    case ShapeKind::kBox:
      *lo = Vector3d(-0.5 * shape.size_m.x(), -0.5 * shape.size_m.y(), 0.0);
      *hi = Vector3d(0.5 * shape.size_m.x(), 0.5 * shape.size_m.y(), shape.size_m.z());
      return;
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum:
      r = std::max(shape.radius_m, shape.top_radius_or_radius_m());
      break;
    case ShapeKind::kSphere:
    case ShapeKind::kCapsule:
      r = shape.radius_m;
      break;
  }
  *lo = Vector3d(-r, -r, 0.0);
  *hi = Vector3d(r, r, shape.total_height_m());
}

void bounding_sphere(const Shape& shape, Vector3d* center, double* radius) {
  switch (shape.kind) {
    case ShapeKind::kBox:
      *center = Vector3d(0, 0, 0.5 * shape.size_m.z());
      *radius = 0.5 * shape.size_m.norm();
      return;
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum: {
      const double r = std::max(shape.radius_m, shape.top_radius_or_radius_m());
      *center = Vector3d(0, 0, 0.5 * shape.height_m);
      *radius = std::hypot(r, 0.5 * shape.height_m);
      return;
    }
    case ShapeKind::kSphere:
      *center = Vector3d(0, 0, shape.radius_m);
      *radius = shape.radius_m;
      return;
    case ShapeKind::kCapsule:
      *center = Vector3d(0, 0, shape.radius_m + 0.5 * shape.height_m);
      *radius = shape.radius_m + 0.5 * shape.height_m;
      return;
  }
}

}  // namespace scenewatch::sim
