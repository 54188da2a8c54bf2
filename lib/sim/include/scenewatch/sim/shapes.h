#pragma once
/// Analytic primitives of the simulator, each in its own local frame: origin at the centre of the
/// base, z up along the axis. Ray intersection (for rendering), signed distance (for contact tests
/// and as an independent oracle of the surfaces) and bounding spheres (for culling).
#include <Eigen/Core>

#include <string>

namespace scenewatch::sim {

/// Kind of primitive. Cylinders and cones are frusta with equal radii or a zero top radius.
enum class ShapeKind { kBox, kCylinder, kFrustum, kSphere, kCapsule };

/// Printable name ("box", "cylinder", "frustum", "sphere", "capsule").
const char* to_string(ShapeKind kind);

/// Size of a primitive; which fields count depends on the kind.
struct Shape {
  ShapeKind kind = ShapeKind::kBox;
  Eigen::Vector3d size_m = Eigen::Vector3d(0.1, 0.1, 0.1);  ///< box: full side lengths
  double radius_m = 0.05;      ///< cylinder, sphere, capsule; frustum: radius at the base
  double top_radius_m = 0.05;  ///< frustum: radius at the top (0: a cone)
  double height_m = 0.1;       ///< cylinder, frustum; capsule: length of the axis segment
  bool open_top = false;       ///< cylinder/frustum: a vessel (cup, glass) open at the top
  double wall_m = 0.004;       ///< vessel wall and bottom thickness

  /// Top radius of a cylinder (its radius) or frustum.
  double top_radius_or_radius_m() const { return kind == ShapeKind::kCylinder ? radius_m : top_radius_m; }
  /// Extent along the local z axis.
  double total_height_m() const;
};

/// A ray hit in the shape's local frame.
struct ShapeHit {
  double t = 0.0;                                     ///< ray parameter: point = origin + t * dir
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< outward unit normal
};

/// Nearest intersection of the ray origin + t * dir (dir need not be unit) with the shape's
/// surface for t in (t_min, t_max). Returns false when there is none.
bool intersect(const Shape& shape, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
               double t_min, double t_max, ShapeHit* hit);

/// Signed distance from a point in the local frame to the surface (negative inside). Exact for
/// closed shapes; for open vessels a bound that is exact on and near the surface.
double signed_distance(const Shape& shape, const Eigen::Vector3d& p_local);

/// Corners (local frame) of an axis-aligned box enclosing the shape.
void bounding_box(const Shape& shape, Eigen::Vector3d* min_local, Eigen::Vector3d* max_local);

/// Centre (local frame) and radius of a sphere enclosing the shape.
void bounding_sphere(const Shape& shape, Eigen::Vector3d* center_local, double* radius_m);

}  // namespace scenewatch::sim
