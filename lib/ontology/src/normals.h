#pragma once
// Surface normals of an object's points.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"

namespace scenewatch::ontology::detail {

/// Unit normals of cloud[indices] (all valid), each from a PCA of its k nearest neighbours among
/// those points only, flipped towards the sensor. Normals that cannot be estimated are NaN.
std::vector<Eigen::Vector3d> estimate_normals(const Cloud& cloud, const std::vector<int>& indices, int k,
                                              const Eigen::Vector3d& sensor_origin);

}  // namespace scenewatch::ontology::detail
