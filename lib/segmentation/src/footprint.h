#pragma once
// Footprints of point sets on a support: their convex hull in the plane and their height range
// along its normal. Used to find what an object stands on.
#include <vector>

#include "hull2d.h"
#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

struct Footprint {
  std::vector<Vec2> points;  ///< the points in the plane's basis
  std::vector<Vec2> hull;
  double low = 0, high = 0;  ///< 5th and 95th percentile of the height along `up`
};

Footprint footprint(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& up);

/// Share of a's points inside b's hull.
double share_inside(const Footprint& a, const Footprint& b);

}  // namespace scenewatch::segmentation
