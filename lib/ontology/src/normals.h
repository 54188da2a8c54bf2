#pragma once
// Surface normals of an object's points.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"

namespace scenewatch::ontology::detail {

/// Unit normals of cloud[indices] (all valid), each from a PCA of its k nearest neighbours among
/// those points only, flipped towards the sensor. Normals that cannot be estimated are NaN.
/// The neighbours are found in a hash grid whose cell is the typical k-th neighbour distance (the
/// median over a sample of the points): exact where a point's k-th neighbour lies within one cell,
/// the nearest of the 27 cells around it elsewhere (sparse spots). No search tree, no allocation
/// per point.
std::vector<Eigen::Vector3d> estimate_normals(const Cloud& cloud, const std::vector<int>& indices, int k,
                                              const Eigen::Vector3d& sensor_origin);

/// The same from PCL's NormalEstimation over a kd-tree (exact k nearest neighbours): the former
/// estimate, kept as the oracle of estimate_normals and the baseline of its benchmark.
std::vector<Eigen::Vector3d> estimate_normals_kdtree(const Cloud& cloud, const std::vector<int>& indices, int k,
                                                     const Eigen::Vector3d& sensor_origin);

}  // namespace scenewatch::ontology::detail
