// Colour edges by OpenCV's Canny with thresholds from the image noise: see colour_edges.h.
#include "colour_edges.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace scenewatch::segmentation {
namespace {

// Immerkaer (1996), eq. (2): sigma = sqrt(pi / 2) / (6 (W - 2) (H - 2)) sum |I * N| with
// N = [1 -2 1; -2 4 -2; 1 -2 1], which cancels any image structure up to second order.
double immerkaer_sigma(const cv::Mat& grey) {
  if (grey.cols < 3 || grey.rows < 3) return 0.0;
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  const cv::Rect inner(1, 1, grey.cols - 2, grey.rows - 2);
  const double sum = cv::sum(cv::abs(response(inner)))[0];
  return std::sqrt(M_PI / 2.0) * sum / (6.0 * inner.area());
}

}  // namespace

ColourEdges::ColourEdges(const Cloud& cloud, int u0, int v0, int u1, int v1, double noise_sigmas)
    : width_(static_cast<int>(cloud.width)), u0_(u0), v0_(v0), w_(std::max(0, u1 - u0 + 1)), h_(std::max(0, v1 - v0 + 1)) {
  edges_.assign(static_cast<std::size_t>(w_) * h_, 0);
  if (w_ < 3 || h_ < 3) return;
  cv::Mat bgr(h_, w_, CV_8UC3);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      const PointT& p = cloud[static_cast<std::size_t>(v + v0_) * width_ + u + u0_];
      bgr.at<cv::Vec3b>(v, u) = cv::Vec3b(p.b, p.g, p.r);
    }
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  noise_sigma_ = immerkaer_sigma(grey);
  // The 3x3 Sobel derivative of white noise of sigma s has a standard deviation of sqrt(12) s
  // (the kernel's squared weights sum to 12); the L2 magnitude of the two derivatives is then
  // Rayleigh distributed with that scale, exceeding k sqrt(2) scales with probability exp(-k^2).
  const double scale = std::sqrt(12.0) * std::max(noise_sigma_, 0.5);
  const double high = noise_sigmas * std::sqrt(2.0) * scale;
  cv::Mat edges;
  cv::Canny(bgr, edges, 0.5 * high, high, 3, /*L2gradient=*/true);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) edges_[static_cast<std::size_t>(v) * w_ + u] = edges.at<std::uint8_t>(v, u) != 0;

}

bool ColourEdges::is_edge(int i) const {
  const int u = i % width_ - u0_, v = i / width_ - v0_;
  return u >= 0 && v >= 0 && u < w_ && v < h_ && edges_[static_cast<std::size_t>(v) * w_ + u] != 0;
}

}  // namespace scenewatch::segmentation
