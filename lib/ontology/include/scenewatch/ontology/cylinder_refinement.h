#pragma once
/// Least-squares refinement of a cylinder seen from one side: Levenberg-Marquardt on the radial
/// residuals |(x - c) x a| - r over axis direction, axis position and radius, with Huber weights,
/// in rounds that re-select the points near the current cylinder.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/fit.h"
#include "scenewatch/ontology/primitive.h"

namespace scenewatch::ontology {

/// A starting cylinder: a point on the axis, the axis, the radius.
struct CylinderGuess {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double radius_m = 0.0;
};

/// Refines `guess` on `points` (with unit `normals` of the same size, oriented towards the sensor,
/// or empty: no normal test).
/// With `fix_axis` the axis stays guess.axis (upright prior) and only position and radius move.
/// `untrusted` (empty, or one flag per point) marks points that do not pull the fit (depth biased
/// near a depth edge) unless fewer than config.min_points others lie near the cylinder; they are
/// still reported among the inliers (height, rms, coverage: the seen surface).
/// The indices of the result are positions in `points`. Empty when fewer than config.min_points
/// points lie near the cylinder or the fit degenerates (radius <= 0 or not finite).
std::optional<CylinderFit> refine_cylinder(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<Eigen::Vector3d>& normals, const CylinderGuess& guess,
                                           bool fix_axis, const FitConfig& config,
                                           const std::vector<char>& untrusted = {});

/// An upright starting cylinder: algebraic circle fit (Kasa) of the points whose normals are
/// within 60 degrees of horizontal, projected along `up`. Empty when too few such points.
std::optional<CylinderGuess> upright_guess(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& up,
                                           const FitConfig& config);

/// Angular extent in degrees (0..360) of directions about `axis` through `point`: 360 minus the
/// largest gap between neighbouring directions.
double angular_coverage_deg(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& point,
                            const Eigen::Vector3d& axis);

}  // namespace scenewatch::ontology
