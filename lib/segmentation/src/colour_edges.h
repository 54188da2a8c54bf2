#pragma once
// Colour edges of an organized cloud's image, in one rectangle (a cluster's bounding box): OpenCV's
// Canny detector (Canny 1986) on the three colour channels, each pixel's gradient taken from the
// channel where it is strongest. Two boxes of different print pressed together, a book of one
// colour on a book of another, meet in such an edge where their shapes continue smoothly.
//
// The thresholds come from the camera's noise, not from a score: the noise of the image itself,
// estimated by Immerkaer's Laplacian-difference operator ("Fast noise variance estimation", CVIU
// 1996), sets the high threshold at `noise_sigmas` standard deviations of the Sobel gradient's
// magnitude on noise alone; the low one is half of it (Canny's own ratio).
#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

/// Edge pixels in one rectangle of an organized cloud's colour image. Thread safe (no state after
/// construction).
class ColourEdges {
 public:
  /// Pixels (u, v) with u in [u0, u1], v in [v0, v1].
  ColourEdges(const Cloud& cloud, int u0, int v0, int u1, int v1, double noise_sigmas = 3.0);
  /// Whether cloud pixel i is an edge pixel (false outside the rectangle).
  bool is_edge(int i) const;
  /// The image noise found, grey levels (1 sigma).
  double noise_sigma() const { return noise_sigma_; }

 private:
  int width_, u0_, v0_, w_, h_;
  double noise_sigma_ = 0.0;
  std::vector<std::uint8_t> edges_;  ///< over the rectangle, row-major
};

}  // namespace scenewatch::segmentation
