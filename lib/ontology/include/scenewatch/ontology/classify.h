#pragma once
/// Classification: each class's primitive is fitted to the object and checked against the class's
/// deformation bounds, residual, coverage and top; the accepted class with the highest score wins.
/// The primitive with the most points is not used: on real views a box can come out best as a
/// sphere and a can as its top face.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/object_class.h"
#include "scenewatch/ontology/shape_fit.h"

namespace scenewatch::ontology {

/// One class tried on one object.
struct ClassMatch {
  std::string class_name;
  bool accepted = false;
  /// The fraction of the object's points the class's primitive explains (within 2 max_rms_m of
  /// its surface, normal agreeing), 0..1; 0 when no primitive could be fitted.
  double score = 0;
  std::string reason;  ///< why it was refused ("radius 81.0 mm outside [25, 70] mm"); empty when accepted
  ShapeFit fit;        ///< the class's primitive fitted to the object (meaningless when score is 0)
};

/// Checks `fit` (of object_class.shape) against the class. `points` and `normals` as for fit_shape.
ClassMatch match_class(const ObjectClass& object_class, const ShapeFit& fit, const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector3d>& normals);

/// A vessel is taken as open when at least this fraction of its points lie on its inside wall.
inline constexpr double kOpenTopMinInnerFraction = 0.03;
/// A box's side normals must fall into two perpendicular directions this well (ShapeFit::side_alignment;
/// a flat face with 15 degrees of normal noise: about 0.7; a round side seen over 90 degrees or more: below 0.3).
inline constexpr double kBoxMinSideAlignment = 0.5;

}  // namespace scenewatch::ontology
