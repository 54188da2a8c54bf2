// Umeyama inside RANSAC.
#include "scenewatch/localization/rigid_ransac.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>

namespace scenewatch::localization {
namespace {

Pose umeyama_fit(const std::vector<Correspondence>& pairs, const std::vector<std::size_t>& use) {
  Eigen::Matrix3Xd src(3, use.size()), dst(3, use.size());
  for (std::size_t i = 0; i < use.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = pairs[use[i]].source;
    dst.col(static_cast<Eigen::Index>(i)) = pairs[use[i]].target;
  }
  Pose T = Pose::Identity();
  T.matrix() = Eigen::umeyama(src, dst, false);
  return T;
}

std::vector<std::size_t> inliers_of(const std::vector<Correspondence>& pairs, const Pose& T) {
  std::vector<std::size_t> in;
  for (std::size_t i = 0; i < pairs.size(); ++i)
    if ((T * pairs[i].source - pairs[i].target).norm() <= pairs[i].tolerance_m) in.push_back(i);
  return in;
}

// Three points far enough apart on both sides, and the same distances on both (a rigid motion
// keeps them): a cheap test that skips most wrong samples before the fit.
bool usable_sample(const std::vector<Correspondence>& pairs, const std::size_t idx[3], double spread_m) {
  for (int a = 0; a < 3; ++a) {
    const auto& p = pairs[idx[a]];
    const auto& q = pairs[idx[(a + 1) % 3]];
    const double ds = (p.source - q.source).norm(), dt = (p.target - q.target).norm();
    if (ds < spread_m || dt < spread_m) return false;
    if (std::abs(ds - dt) > p.tolerance_m + q.tolerance_m) return false;
  }
  return true;
}

}  // namespace

RigidFit fit_rigid_ransac(const std::vector<Correspondence>& pairs, const RansacConfig& config) {
  RigidFit best;
  if (pairs.size() < 3) return best;
  std::mt19937 rng(config.seed);
  std::uniform_int_distribution<std::size_t> pick(0, pairs.size() - 1);
  for (int it = 0; it < config.iterations; ++it) {
    std::size_t idx[3] = {pick(rng), pick(rng), pick(rng)};
    if (idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2]) continue;
    if (!usable_sample(pairs, idx, config.min_sample_spread_m)) continue;
    const Pose T = umeyama_fit(pairs, {idx[0], idx[1], idx[2]});
    auto in = inliers_of(pairs, T);
    if (in.size() > best.inliers.size()) {
      best.T_target_source = T;
      best.inliers = std::move(in);
    }
  }
  if (best.inliers.size() < 3) return RigidFit{};
  // Refit to all inliers twice: the consensus of the refit may grow.
  for (int round = 0; round < 2; ++round) {
    const Pose T = umeyama_fit(pairs, best.inliers);
    auto in = inliers_of(pairs, T);
    if (in.size() < best.inliers.size()) break;
    best.T_target_source = T;
    best.inliers = std::move(in);
  }
  double sum = 0.0;
  for (std::size_t i : best.inliers) sum += (best.T_target_source * pairs[i].source - pairs[i].target).squaredNorm();
  best.rms_m = std::sqrt(sum / static_cast<double>(best.inliers.size()));
  return best;
}

}  // namespace scenewatch::localization
