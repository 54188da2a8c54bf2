#pragma once
// Point statistics of a part of a cluster (a convex part, a region between boundaries): its width
// across its second principal axis tells an object from a fragment along a crease or an edge.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace scenewatch::segmentation {

/// Running sums of a part's points. Its width is the extent across its second principal axis
/// (sqrt(12 var) for points spread evenly over that width).
struct PartShape {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
  double count = 0;
  void add(const Eigen::Vector3d& q) {
    sum += q;
    sum_sq += q * q.transpose();
    count += 1;
  }
  /// Metres; 0 below three points.
  double width() const {
    if (count < 3) return 0.0;
    const Eigen::Vector3d mean = sum / count;
    const Eigen::Matrix3d cov = sum_sq / count - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(cov, Eigen::EigenvaluesOnly);
    return std::sqrt(12.0 * std::max(0.0, es.eigenvalues()(1)));
  }
};

}  // namespace scenewatch::segmentation
