// Drifting and noisy pose sources, for measuring localization.
#include "scenewatch/localization/pose_error.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "scenewatch/localization/dense_alignment.h"

namespace scenewatch::localization {
namespace {

struct TwistNoise {
  std::mt19937 rng;
  std::normal_distribution<double> t, r;
  TwistNoise(double rms_m, double rms_deg, unsigned seed)
      : rng(seed), t(0.0, rms_m / std::sqrt(3.0)), r(0.0, rms_deg * M_PI / 180.0 / std::sqrt(3.0)) {}
  Pose draw() {
    Eigen::Matrix<double, 6, 1> xi;
    xi << t(rng), t(rng), t(rng), r(rng), r(rng), r(rng);
    return twist_exp(xi);
  }
};

}  // namespace

std::vector<Pose> with_drift(const std::vector<Pose>& truth, double step_m, double step_deg, unsigned seed) {
  if (truth.empty()) return {};
  TwistNoise noise(step_m, step_deg, seed);
  std::vector<Pose> out{truth.front()};
  for (std::size_t i = 1; i < truth.size(); ++i) out.push_back(Pose(out.back() * truth[i - 1].inverse() * truth[i] * noise.draw()));
  return out;
}

std::vector<Pose> with_noise(const std::vector<Pose>& truth, double sigma_m, double sigma_deg, unsigned seed) {
  TwistNoise noise(sigma_m, sigma_deg, seed);
  std::vector<Pose> out;
  for (const Pose& p : truth) out.push_back(Pose(p * noise.draw()));
  return out;
}

double trajectory_rmse_m(const std::vector<Pose>& estimate, const std::vector<Pose>& truth) {
  const std::size_t n = std::min(estimate.size(), truth.size());
  if (n == 0) return 0.0;
  const Pose e0 = estimate.front().inverse(), g0 = truth.front().inverse();
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += ((e0 * estimate[i]).translation() - (g0 * truth[i]).translation()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(n));
}

}  // namespace scenewatch::localization
