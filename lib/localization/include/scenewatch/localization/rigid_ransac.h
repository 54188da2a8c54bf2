#pragma once
/// A rigid motion from 3D-3D correspondences with outliers: Umeyama's closed form (Arun et al.
/// 1987, Umeyama 1991; Eigen::umeyama without scale) on minimal samples of three inside RANSAC
/// (Fischler and Bolles 1981), then refitted to all inliers.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/geometry.h"

namespace scenewatch::localization {

struct Correspondence {
  Eigen::Vector3d target;  ///< point in the frame the motion maps to
  Eigen::Vector3d source;  ///< the same point in the frame it maps from
  /// Largest distance |T source - target| at which the pair still agrees (its noise, a few sigmas).
  double tolerance_m = 0.05;
};

struct RansacConfig {
  int iterations = 400;
  /// A sample whose three points span less than this (the shortest side) is degenerate.
  double min_sample_spread_m = 0.05;
  std::uint32_t seed = 1;  ///< fixed: the same input gives the same answer
};

struct RigidFit {
  Pose T_target_source = Pose::Identity();
  std::vector<std::size_t> inliers;  ///< indices into the correspondences
  double rms_m = 0.0;                ///< of the inliers after the refit
};

/// The motion most correspondences agree with; no inliers when fewer than three pairs are given
/// or no sample was usable.
RigidFit fit_rigid_ransac(const std::vector<Correspondence>& pairs, const RansacConfig& config = {});

}  // namespace scenewatch::localization
