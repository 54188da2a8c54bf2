#pragma once
/// An object class of the ontology: a name, a parametric primitive with the deformation it allows
/// (ranges of its parameters), grasp points defined on that primitive and the motions the class
/// allows. Classes come from config/ontology.yaml, from DefineClass, and from the class store.
#include <string>
#include <vector>

#include "scenewatch/core/result.h"

namespace scenewatch::ontology {

/// The parametric primitive of a class.
enum class ClassShape {
  kCylinder,  ///< radius, height, axis
  kFrustum,   ///< a cylinder whose radius changes linearly with height (cups that taper)
  kSphere,    ///< radius
  kBox,       ///< three edge lengths, upright (sides vertical)
};

/// "cylinder", "frustum", "sphere", "box".
const char* to_string(ClassShape shape);

/// A closed interval [min, max] of a parameter (metres or degrees as its name says).
struct Range {
  double min = 0.0;
  double max = 0.0;
  bool contains(double v) const { return v >= min && v <= max; }
};

/// How the class's axis stands (cylinder, frustum; a box's height edge).
enum class ClassAxis {
  kAny,      ///< any direction
  kUpright,  ///< along the support's normal, within axis_tolerance_deg
};

/// Whether a vessel's top is open (a cup: its inside is seen) or closed (a can).
enum class ClassTop { kAny, kOpen, kClosed };

/// Where a grasp sits on the primitive.
enum class GraspKind {
  kSide,  ///< across the primitive at a height fraction (0 bottom, 1 top), approaching horizontally
  kRim,   ///< on the top edge nearest the sensor, approaching from above, closing across the wall
  kTop,   ///< on the top face's centre, approaching from above
};

/// "side", "rim", "top".
const char* to_string(GraspKind kind);

/// A grasp defined on the class's primitive.
struct GraspDefinition {
  std::string name;               ///< e.g. "side_mid"
  GraspKind kind = GraspKind::kSide;
  double height_fraction = 0.5;   ///< kSide: where along the height, 0 (bottom) .. 1 (top)
};

/// One object class.
struct ObjectClass {
  std::string name;               ///< unique, [a-z0-9_]+
  ClassShape shape = ClassShape::kCylinder;
  // Allowed deformation. Cylinder and frustum: radius (frustum: the mean of bottom and top) and
  // height; frustum also taper_deg (half angle; positive: wider at the top); sphere: radius; box:
  // size_m (sorted edge lengths, shortest first, each within its range) with height separately.
  Range radius_m{0.0, 0.0};
  Range height_m{0.0, 0.0};
  Range taper_deg{0.0, 0.0};
  std::vector<Range> size_m;      ///< box: 2 ranges, the horizontal edges (shorter, longer)
  ClassAxis axis = ClassAxis::kUpright;
  double axis_tolerance_deg = 15.0;
  ClassTop top = ClassTop::kAny;
  // Acceptance of a fit (the primitive against the object's points).
  double max_rms_m = 0.004;       ///< root mean square distance of the explained points
  double min_explained = 0.6;     ///< fraction of the object's points within 2 rms_tolerance of the surface
  double min_coverage_deg = 60;   ///< cylinder/frustum/sphere: seen arc about the axis
  std::vector<GraspDefinition> grasps;
  /// The motions the class allows (from the foreground's learnt DoF constraints; today set by
  /// config or DefineClass): any of "x", "y", "z", "roll", "pitch", "yaw".
  std::vector<std::string> allowed_dofs;
  std::string description;        ///< free text
};

/// Checks names, ranges and fields of the class's shape; the message names the class and field
/// ("classes[cup].radius_m: min must be <= max").
Status validate(const ObjectClass& object_class);

}  // namespace scenewatch::ontology
