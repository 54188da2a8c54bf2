#pragma once
/// What makes the surprise of a real camera honest: a per-frame photometric correction (auto
/// exposure and white balance shift the whole image) and tolerance of the misalignment that is
/// left after the pose (a few pixels along texture edges and depth discontinuities). Both keep a
/// real change: a new object differs from the memory over an area, not by a global gain or along
/// a thin edge.
#include <array>
#include <cstddef>
#include <vector>

#include "scenewatch/core/image.h"
#include "scenewatch/surprise/bayes.h"
#include "scenewatch/surprise/expected_view.h"

namespace scenewatch::surprise {

struct RobustConfig {
  /// Fit observed = gain * expected + offset per opponent channel on the pixels that agree, and
  /// compare the observation mapped back into the memory's photometry.
  bool photometric = true;
  /// A surprising pixel is explained when the expected samples of a pixel this close (per 640
  /// pixels of width) predict its colour: the surprise is the least over that window. 0: off.
  int align_radius_px = 2;
  /// Pixels below this total KL (nats) are not re-examined (they cannot start or grow a region
  /// when it is at most the regions' threshold_low).
  double align_min_kl = 6.0;
};

Status validate(const RobustConfig& config);

/// A per-channel affine map of the observed opponent signal onto the expected one.
struct Photometric {
  std::array<float, kChannels> gain{1.0f, 1.0f, 1.0f};
  std::array<float, kChannels> offset{0.0f, 0.0f, 0.0f};
  std::size_t pixels = 0;  ///< agreeing pixels the fit used (0: identity, too few)
  /// Observed value in the memory's photometry.
  float apply(int channel, float observed) const { return (observed - offset[channel]) / gain[channel]; }
};

/// Robust fit (least squares, then again on the pixels within 2.5 robust sigmas) on a subsample
/// of the pixels with expected samples. Gains are limited to [0.5, 2]: beyond, the scene itself
/// changed, and that is what should be reported.
Photometric fit_photometric(const ExpectedView& view, const ColorImage& observed, int min_samples);

}  // namespace scenewatch::surprise
