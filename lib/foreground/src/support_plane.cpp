// RANSAC (Fischler & Bolles 1981) on a fixed subsample with a least-squares refit on the inliers;
// planes are found one after another with the previous inliers removed.
#include "support_plane.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "scenewatch/core/plane_fit.h"

namespace scenewatch::foreground {
namespace {

constexpr std::size_t kMaxScoringPoints = 800;
/// Adaptive stop (Fischler & Bolles 1981; Hartley & Zisserman, alg. 4.5): enough samples for a
/// 99.9% chance that one of them was all inliers, given the best inlier ratio so far.
constexpr double kConfidence = 0.999;
constexpr int kMinIterations = 40;

/// Small deterministic generator: the same frame gives the same planes.
struct Lcg {
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  std::uint32_t next() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::uint32_t>(state >> 33);
  }
};

bool plane_through(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, SupportPlane* plane) {
  Eigen::Vector3f n = (b - a).cross(c - a);
  const float norm = n.norm();
  if (!(norm > 1e-9f)) return false;
  n /= norm;
  plane->normal = n;
  plane->d = -n.dot(a);
  return true;
}

/// Least-squares plane through the points (plane_fit.h). The solver's normal is taken as it is,
/// not normalized again (segmentation's supports normalize theirs).
bool refit(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& members, SupportPlane* plane) {
  if (members.size() < 3) return false;
  const PlaneFit fit = fit_plane_least_squares(points, members);
  const Eigen::Vector3d& n = fit.normal;
  plane->normal = n.cast<float>();
  plane->d = static_cast<float>(-n.dot(fit.mean));
  return true;
}

}  // namespace

std::size_t min_plane_inliers(const SupportPlaneConfig& config, std::size_t valid_points) {
  return std::max<std::size_t>(50, static_cast<std::size_t>(config.min_fraction * valid_points));
}

namespace {

void orient_towards_camera(SupportPlane* plane) {
  if (plane->d < 0) {
    plane->normal = -plane->normal;
    plane->d = -plane->d;
  }
}

}  // namespace

std::vector<SupportPlane> find_support_planes(const std::vector<Eigen::Vector3f>& points,
                                              const std::vector<std::uint8_t>& valid, int width, int height,
                                              const SupportPlaneConfig& config, std::vector<std::uint8_t>* on_plane) {
  on_plane->assign(points.size(), 0);
  std::vector<SupportPlane> planes;
  std::vector<int> remaining;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (valid[i]) remaining.push_back(static_cast<int>(i));
  }
  const std::size_t total = remaining.size();
  const std::size_t min_inliers = min_plane_inliers(config, total);
  Lcg rng;
  for (int round = 0; round < config.max_planes && remaining.size() >= min_inliers; ++round) {
    // Score hypotheses on an evenly spaced subsample; count exactly on all remaining points after.
    std::vector<int> sample;
    const std::size_t stride = std::max<std::size_t>(1, remaining.size() / kMaxScoringPoints);
    for (std::size_t i = 0; i < remaining.size(); i += stride) sample.push_back(remaining[i]);
    SupportPlane best;
    std::size_t best_count = 0;
    int needed = config.iterations;
    for (int it = 0; it < needed; ++it) {
      const int a = remaining[rng.next() % remaining.size()];
      const int b = remaining[rng.next() % remaining.size()];
      const int c = remaining[rng.next() % remaining.size()];
      SupportPlane hypothesis;
      if (!plane_through(points[a], points[b], points[c], &hypothesis)) continue;
      if (std::abs(hypothesis.normal.y()) < config.min_abs_normal_y) continue;
      if (std::abs(hypothesis.d) < config.min_camera_distance_m) continue;
      std::size_t count = 0;
      for (int i : sample) count += std::abs(hypothesis.distance(points[i])) < config.tolerance_at(points[i].z());
      if (count > best_count) {
        best_count = count;
        best = hypothesis;
        const double w = static_cast<double>(count) / sample.size();
        const double all_inliers = w * w * w;
        if (all_inliers > 1e-9 && all_inliers < 1.0) {
          const double n = std::log(1.0 - kConfidence) / std::log(1.0 - all_inliers);
          needed = std::min(config.iterations, std::max({it + 1, kMinIterations, static_cast<int>(std::ceil(n))}));
        }
      }
    }
    if (best_count < 3) break;
    std::vector<int> inliers, outliers;
    for (int i : remaining) (std::abs(best.distance(points[i])) < config.tolerance_at(points[i].z()) ? inliers : outliers).push_back(i);
    for (int pass = 0; pass < 3; ++pass) {  // least squares on the inliers, while it gains inliers
      SupportPlane refined = best;
      if (!refit(points, inliers, &refined) || std::abs(refined.normal.y()) < config.min_abs_normal_y ||
          std::abs(refined.d) < config.min_camera_distance_m) {
        break;
      }
      std::vector<int> refined_inliers, refined_outliers;
      for (int i : remaining) {
        (std::abs(refined.distance(points[i])) < config.tolerance_at(points[i].z()) ? refined_inliers : refined_outliers).push_back(i);
      }
      if (refined_inliers.size() < inliers.size()) break;
      best = refined;
      inliers.swap(refined_inliers);
      outliers.swap(refined_outliers);
    }
    remaining.swap(outliers);  // all inliers leave, so the next round finds another plane
    const std::size_t kept = keep_large_patches(points, inliers, width, height, config, total, min_inliers, on_plane);
    if (kept == 0) continue;
    best.inliers = kept;
    orient_towards_camera(&best);
    planes.push_back(best);
  }
  return planes;
}

std::size_t keep_large_patches(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& inliers, int width,
                               int height, const SupportPlaneConfig& config, std::size_t total, std::size_t min_inliers,
                               std::vector<std::uint8_t>* on_plane) {
  // Keep the large connected patches of inliers (8-connected on the grid).
  cv::Mat mask(height, width, CV_8U, cv::Scalar(0));
  for (int i : inliers) mask.data[i] = 1;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  const int min_patch = std::max(20, static_cast<int>(config.min_patch_fraction * total));
  std::vector<Eigen::Vector3d> sum(static_cast<std::size_t>(count), Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> outer(static_cast<std::size_t>(count), Eigen::Matrix3d::Zero());
  for (int i : inliers) {
    const int c = labels.ptr<int>()[i];
    const Eigen::Vector3d q = points[i].cast<double>();
    sum[c] += q;
    outer[c] += q * q.transpose();
  }
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(count), 0);
  std::size_t kept = 0;
  for (int c = 1; c < count; ++c) {
    const int area = stats.at<int>(c, cv::CC_STAT_AREA);
    if (area < min_patch) continue;
    const Eigen::Vector3d mean = sum[c] / area;
    const Eigen::Matrix3d cov = outer[c] / area - mean * mean.transpose();
    const Eigen::Vector3d spread = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov, Eigen::EigenvaluesOnly).eigenvalues();
    if (std::sqrt(std::max(0.0, spread(1))) < config.min_patch_width_m) continue;
    keep[c] = 1;
    kept += static_cast<std::size_t>(area);
  }
  if (kept < min_inliers) return 0;
  for (int i : inliers) {
    if (keep[labels.ptr<int>()[i]]) (*on_plane)[i] = 1;
  }
  return kept;
}

}  // namespace scenewatch::foreground
