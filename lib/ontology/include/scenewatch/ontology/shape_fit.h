#pragma once
/// A class's parametric primitive fitted to one object's points (cylinder, frustum, sphere,
/// upright box), and how well it explains them. One fit per shape serves every class of that shape.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/fit.h"
#include "scenewatch/ontology/object_class.h"

namespace scenewatch::ontology {

/// A fitted primitive, a closed solid, in the frame of the points.
struct ShapeFit {
  ClassShape shape = ClassShape::kCylinder;
  /// Cylinder, frustum, box: centre of the solid (on the axis, at mid height); sphere: centre.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();    ///< unit; cylinder, frustum, box: bottom to top
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();  ///< box: unit, along its shorter horizontal edge
  double radius_m = 0;         ///< cylinder, sphere; frustum: mean of bottom and top radius
  double bottom_radius_m = 0;  ///< frustum (cylinder: = radius_m)
  double top_radius_m = 0;     ///< frustum (cylinder: = radius_m)
  double taper_deg = 0;        ///< frustum: half angle, positive when wider at the top
  double height_m = 0;         ///< cylinder, frustum, box
  Eigen::Vector2d size_m = Eigen::Vector2d::Zero();  ///< box: horizontal edges, shorter first
  // How well it explains the object.
  /// rms surface distance of the points within 1 cm of the surface; cylinder and frustum: of
  /// those on the side only (normal facing outwards), whose residual the caps do not dilute
  double rms_m = 0;
  double coverage_deg = 0;     ///< seen arc about the axis (sphere: about the up direction); box: 360
  double axis_tilt_deg = 0;    ///< angle between axis and up (sphere: 0)
  /// Cylinder and frustum: fraction of the points seen on the inside wall (radially inside, normal
  /// pointing to the axis): an open vessel shows it, a closed can does not.
  double inner_fraction = 0;
  /// Box: how well the side normals fall into two perpendicular directions, 0..1 (the mean
  /// resultant length of four times their azimuth): near 1 for a box, low for a round side.
  double side_alignment = 0;
};

/// The solid's unsigned surface distance of p and the surface normal at the nearest point.
double surface_distance(const ShapeFit& fit, const Eigen::Vector3d& p, Eigen::Vector3d* normal = nullptr);

/// Fraction of `points` within `distance_m` of the surface whose normal is within ~32 degrees
/// (|cos| >= 0.85) of the surface normal there.
double explained_fraction(const ShapeFit& fit, const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector3d>& normals, double distance_m);

/// Fits `shape` to the object. `points` and `normals` (unit, towards the sensor) are the sample of
/// fit_object (ObjectFit::sample_points, sample_normals), `object` its result (its refined cylinder
/// starts the cylinder and the frustum), `up` the support's normal. Empty when the shape cannot be
/// fitted (no cylinder for a cylinder or frustum, a degenerate sphere, no side faces for a box).
std::optional<ShapeFit> fit_shape(ClassShape shape, const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& normals, const ObjectFit& object,
                                  const Eigen::Vector3d& up);

}  // namespace scenewatch::ontology
