#pragma once
/// The least-squares plane through a set of points (issue 33): their mean and the eigenvector of
/// their scatter matrix with the smallest eigenvalue. One fit for the foreground's support planes
/// (hand detection) and segmentation's supporting planes, which each finish it their own way.
#include <vector>

#include <Eigen/Core>

namespace scenewatch {

/// A plane as the least-squares fit gives it: the points' mean and the smallest eigenvector of
/// their scatter, as Eigen's SelfAdjointEigenSolver returns it: unit length only up to rounding,
/// and of either sign. The plane is normal . p + d = 0 with d = -normal . mean; callers normalize
/// and orient the normal as they need (segmentation normalizes it, the foreground does not).
struct PlaneFit {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// Fits a plane to points[i] for i in `members` (at least one; three or more for a plane that
/// means anything). Sums in double, in the order of `members`.
PlaneFit fit_plane_least_squares(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& members);

}  // namespace scenewatch
