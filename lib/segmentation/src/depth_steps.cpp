// Depth steps between neighbouring pixels: see depth_steps.h.
#include "depth_steps.h"

#include "scenewatch/core/depth_validity.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch::segmentation {
namespace {

// Pixels a side's line runs through: a structured-light sensor correlates 9x9 windows, so its
// depth is smooth over about 4 pixels, and a side that long averages over the terraces its
// disparity steps leave on a slanted surface.
constexpr int kSidePixels = 5;

}  // namespace

DepthSteps::DepthSteps(const Cloud& cloud, const Eigen::Vector3d& sensor_origin, const DepthStepParams& params, int u0,
                       int v0, int u1, int v1)
    : cloud_(cloud), origin_(sensor_origin.cast<float>()), params_(params) {
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  u0_ = std::max(0, u0 - kSidePixels);
  v0_ = std::max(0, v0 - kSidePixels);
  w_ = std::min(width - 1, u1 + kSidePixels) - u0_ + 1;
  h_ = std::min(height - 1, v1 + kSidePixels) - v0_ + 1;
  ranges_.assign(static_cast<std::size_t>(std::max(0, w_)) * std::max(0, h_), std::numeric_limits<float>::quiet_NaN());
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      const PointT& p = cloud[static_cast<std::size_t>(v + v0_) * width + u + u0_];
      if (is_valid(p)) ranges_[static_cast<std::size_t>(v) * w_ + u] = (p.getVector3fMap() - origin_).norm();
    }
  // The hole band of core/depth_validity.h at the rule's 3 sigma. Its focal length only sets the
  // depth-edge bits, which are not used here: the pixel spacing across the ray at a pixel's range.
  std::vector<float> focal_samples;
  for (int v = 0; v < h_; v += 4)
    for (int u = 0; u + 1 < w_; u += 4) {
      const std::size_t i = static_cast<std::size_t>(v + v0_) * width + u + u0_;
      if (std::isnan(ranges_[static_cast<std::size_t>(v) * w_ + u]) || !is_valid(cloud[i + 1])) continue;
      const float spacing = (cloud[i + 1].getVector3fMap() - cloud[i].getVector3fMap()).norm();
      if (spacing > 0) focal_samples.push_back(ranges_[static_cast<std::size_t>(v) * w_ + u] / spacing);
    }
  double focal_px = 525.0;
  if (!focal_samples.empty()) {
    std::nth_element(focal_samples.begin(), focal_samples.begin() + focal_samples.size() / 2, focal_samples.end());
    focal_px = focal_samples[focal_samples.size() / 2];
  }
  const DepthValidity validity = depth_validity(ranges_, w_, h_, focal_px, params_.sensor, params_.noise_sigmas);
  off_hole_.resize(ranges_.size());
  for (std::size_t i = 0; i < ranges_.size(); ++i) off_hole_[i] = (validity.bits[i] & DepthValidity::kOffHole) != 0;
}

bool DepthSteps::off_hole(int i) const {
  const int width = static_cast<int>(cloud_.width);
  const int u = i % width - u0_, v = i / width - v0_;
  return u >= 0 && v >= 0 && u < w_ && v < h_ && off_hole_[static_cast<std::size_t>(v) * w_ + u];
}

float DepthSteps::range(int i) const {
  const int width = static_cast<int>(cloud_.width);
  const int u = i % width - u0_, v = i / width - v0_;
  if (u < 0 || v < 0 || u >= w_ || v >= h_) return std::numeric_limits<float>::quiet_NaN();
  return ranges_[static_cast<std::size_t>(v) * w_ + u];
}

// Pixels at x = 0 (first), 1, ... away from the boundary at x = -1/2. The least-squares line
// through them, evaluated at the boundary; its variance over the pixel noise's is
// 1/n + (x0 - mean)^2 / Sxx (0.83 for five pixels, 1 for one, where the side's value is the
// pixel's own range).
DepthSteps::Side DepthSteps::fit(int first, int away) const {
  const int width = static_cast<int>(cloud_.width);
  // Walk the padded rectangle: a step of du, dv per pixel; the walk ends at its border.
  const int du = away == 1 ? 1 : away == -1 ? -1 : 0, dv = du == 0 ? (away > 0 ? 1 : -1) : 0;
  int u = first % width - u0_, v = first / width - v0_;
  double r[kSidePixels] = {};
  int n = 0;
  for (; n < kSidePixels && u >= 0 && v >= 0 && u < w_ && v < h_; ++n, u += du, v += dv) {
    const float q = ranges_[static_cast<std::size_t>(v) * w_ + u];
    if (std::isnan(q)) break;
    r[n] = q;
  }
  Side s;
  s.pixels = n;
  s.at_boundary = r[0];
  if (n < 2) return s;
  // x = 0 .. n-1: mean (n - 1) / 2, Sxx = n (n^2 - 1) / 12.
  const double mean_x = 0.5 * (n - 1), sxx = n * (n * n - 1) / 12.0;
  double mean_r = 0, sxr = 0;
  for (int k = 0; k < n; ++k) mean_r += r[k];
  mean_r /= n;
  for (int k = 0; k < n; ++k) sxr += (k - mean_x) * (r[k] - mean_r);
  s.slope = sxr / sxx;
  const double x0 = -0.5;
  s.at_boundary = mean_r + s.slope * (x0 - mean_x);
  s.variance = 1.0 / n + (x0 - mean_x) * (x0 - mean_x) / sxx;
  if (n > 2) {
    double sum_sq = 0;
    for (int k = 0; k < n; ++k) {
      const double e = r[k] - (mean_r + s.slope * (k - mean_x));
      sum_sq += e * e;
    }
    s.scatter = sum_sq / (n - 2);
  }
  return s;
}

// The sensor's axial noise at the side's range and incidence (Nguyen's eq. 2), with the lateral
// noise of the pixel's position carried along the slope (a grazing surface changes range fast
// across one pixel), as a variance.
double DepthSteps::model_variance(const Side& s, int first, int away) const {
  const double r0 = range(first);
  if (s.pixels < 2) return params_.sensor.sigma_z(r0) * params_.sensor.sigma_z(r0);
  // Incidence from the slope: range change per pixel against the lateral spacing of two pixels.
  const Eigen::Vector3f p0 = cloud_[first].getVector3fMap(), p1 = cloud_[first + away].getVector3fMap();
  const Eigen::Vector3f ray = (p0 - origin_).normalized();
  const double lateral = ((p1 - p0) - ray * ray.dot(p1 - p0)).norm();
  const double incidence = lateral > 0 ? std::atan(std::abs(s.slope) / lateral) : M_PI / 2;
  const double axial = params_.sensor.sigma_z(r0, incidence);
  const double along = params_.sensor.lateral_sigma_px(incidence) * std::abs(s.slope);
  return axial * axial + along * along;
}

bool DepthSteps::clean_rim(const Side& s, double model_variance) const {
  const double k = params_.noise_sigmas;
  return s.pixels >= 3 && s.scatter <= k * k * model_variance;
}

bool DepthSteps::is_step(int a, int offset) const {
  const int b = a + offset;
  // A step shows first as a jump between the two pixels themselves, beyond their own noise
  // (most pairs lie on one surface and stop here) ...
  const float ra = range(a), rb = range(b);
  if (std::isnan(ra) || std::isnan(rb)) return false;
  if (std::abs(ra - rb) <= params_.noise_sigmas * std::sqrt(2.0) * params_.sensor.sigma_z(std::min(ra, rb))) return false;
  // ... and then the surfaces on its two sides, carried to the boundary, miss each other.
  const Side left = fit(a, -offset);
  const Side right = fit(b, offset);
  // Beside a hole, a pixel may be the ragged rim of a measurement. It is evidence only when the
  // surface on each side is measured right up to the pair, over three pixels or more, and lies on its
  // line within the sensor's noise: the rim of a real surface, not a stereo camera's frayed one.
  // (A structured-light sensor leaves its projector's shadow beside nearly every occluding edge,
  // so most object-on-object steps have a hole within a few pixels.)
  const double model_l = model_variance(left, a, -offset), model_r = model_variance(right, b, offset);
  if ((!off_hole(a) || !off_hole(b)) && !(clean_rim(left, model_l) && clean_rim(right, model_r))) return false;
  const double miss = std::abs(left.at_boundary - right.at_boundary);
  // Each side's pixel noise: the model's, or the scatter about its line when that is larger (a
  // shiny or dark surface).
  const double sl2 = std::max(model_l, left.scatter), sr2 = std::max(model_r, right.scatter);
  const double sigma = std::sqrt(left.variance * sl2 + right.variance * sr2);
  return miss > params_.noise_sigmas * sigma;
}

}  // namespace scenewatch::segmentation
