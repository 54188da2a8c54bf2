#pragma once
// Planar geometry for the segmentation: a basis of a plane, convex hulls of footprints.
#include <Eigen/Geometry>

#include <vector>

namespace scenewatch::segmentation {

using Vec2 = Eigen::Vector2d;

/// An orthonormal basis (u, v) of the plane with normal n.
void plane_basis(const Eigen::Vector3d& n, Eigen::Vector3d& u, Eigen::Vector3d& v);

/// Andrew's monotone chain; counter-clockwise, no repeated end point.
std::vector<Vec2> convex_hull(std::vector<Vec2> pts);

double polygon_area(const std::vector<Vec2>& poly);

/// Inside or on the border of a counter-clockwise convex polygon (false for fewer than 3 corners).
bool inside_convex(const std::vector<Vec2>& hull, const Vec2& p);

}  // namespace scenewatch::segmentation
