// The least-squares plane (plane_fit.h): the smallest eigenvector of the points' scatter about
// their mean (Pearson 1901, "On lines and planes of closest fit").
#include "scenewatch/core/plane_fit.h"

#include <Eigen/Eigenvalues>

namespace scenewatch {

PlaneFit fit_plane_least_squares(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& members) {
  PlaneFit fit;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : members) mean += points[i].cast<double>();
  mean /= static_cast<double>(members.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : members) {
    const Eigen::Vector3d q = points[i].cast<double>() - mean;
    cov += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  fit.mean = mean;
  fit.normal = solver.eigenvectors().col(0);
  return fit;
}

}  // namespace scenewatch
