#pragma once
/// Completion: the fitted primitive's whole surface, sampled evenly. It stands for the object's
/// unseen side too, and carries none of the sensor's noise.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/shape_fit.h"

namespace scenewatch::ontology {

/// Spacing is widened so that a surface gets about this many points at most.
inline constexpr std::size_t kMaxCompletedPoints = 200000;

/// Points on the surface of `fit` about `spacing_m` apart (cylinder and frustum: side, bottom and,
/// unless `open_top`, top; box: six faces; sphere: a Fibonacci lattice), or further apart when the
/// surface would need more than kMaxCompletedPoints. `spacing_m` > 0.
std::vector<Eigen::Vector3d> complete_surface(const ShapeFit& fit, double spacing_m, bool open_top);

}  // namespace scenewatch::ontology
