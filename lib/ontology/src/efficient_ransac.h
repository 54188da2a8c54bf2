#pragma once
// CGAL's Efficient RANSAC behind a CGAL-free interface: the one translation unit that
// instantiates CGAL's templates is efficient_ransac.cpp.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/fit.h"

namespace scenewatch::ontology::detail {

/// Detects planes, cylinders, spheres and cones among points with unit normals. The indices of
/// the returned primitives are positions in `points` (the caller maps them to its cloud); rms_m is
/// left for the caller. Shapes in CGAL's order of detection.
std::vector<Primitive> detect_shapes(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals, const FitConfig& config);

}  // namespace scenewatch::ontology::detail
