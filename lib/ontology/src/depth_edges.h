#pragma once
// Points of an organized cloud near a depth discontinuity, whose depth a structured-light sensor
// biases (its correlation window straddles the edge).
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"

namespace scenewatch::ontology::detail {

/// Per index of `indices` (valid points of `cloud`): 1 when the pixel lies within `margin_deg`,
/// seen from `sensor_origin`, of a depth discontinuity: an invalid pixel, or two 4-neighbours whose
/// distances to the sensor differ by more than `jump_m` (any frame: the cloud may be in world
/// coordinates). The margin becomes pixels (chessboard distance) by the angle between neighbouring
/// pixels' rays, measured on the object. All 0 for an unorganized cloud or a margin under half a
/// pixel.
std::vector<char> near_depth_edge(const Cloud& cloud, const std::vector<int>& indices, double margin_deg, double jump_m,
                                  const Eigen::Vector3d& sensor_origin);

/// The median angle in radians between the rays (from `sensor_origin`) of horizontally neighbouring
/// valid pixels among up to 64 of `indices`; 0 when none has a valid right neighbour.
double pixel_angle_rad(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& sensor_origin);

}  // namespace scenewatch::ontology::detail
