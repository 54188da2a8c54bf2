#include "scenewatch/surprise/robust.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::surprise {
namespace {

constexpr std::size_t kMinFitPixels = 500;
constexpr float kMinGain = 0.5f, kMaxGain = 2.0f;

struct Line {
  float gain = 1.0f, offset = 0.0f;
};

Line least_squares(const std::vector<float>& x, const std::vector<float>& y, const std::vector<char>& use) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!use[i]) continue;
    n += 1;
    sx += x[i];
    sy += y[i];
    sxx += double(x[i]) * x[i];
    sxy += double(x[i]) * y[i];
  }
  Line l;
  const double var = n * sxx - sx * sx;
  if (n < kMinFitPixels || var <= 1e-9 * n * n) {
    // No spread to fit a gain on (a flat-coloured view): an offset only.
    if (n > 0) l.offset = static_cast<float>((sy - sx) / n);
    return l;
  }
  l.gain = static_cast<float>((n * sxy - sx * sy) / var);
  l.offset = static_cast<float>((sy - l.gain * sx) / n);
  return l;
}

}  // namespace

Status validate(const RobustConfig& c) {
  if (c.align_radius_px < 0 || c.align_radius_px > 8) return invalid_argument("surprise.align_radius_px must be in [0, 8]");
  if (!(c.align_min_kl >= 0)) return invalid_argument("surprise.align_min_kl must be >= 0");
  return {};
}

Photometric fit_photometric(const ExpectedView& view, const ColorImage& observed, int min_samples) {
  Photometric p;
  const std::size_t n = view.pixel_count();
  if (observed.rgb.size() != 3 * n) return p;
  // Every 3rd pixel of every 3rd row is plenty (34,000 at VGA) and keeps this under a millisecond.
  std::array<std::vector<float>, kChannels> x, y;
  for (int v = 0; v < view.height; v += 3) {
    for (int u = 0; u < view.width; u += 3) {
      const std::size_t i = static_cast<std::size_t>(v) * view.width + u;
      if (view.count[i] < std::max(1, min_samples)) continue;
      float opp[kChannels];
      to_opponent(observed.rgb[3 * i], observed.rgb[3 * i + 1], observed.rgb[3 * i + 2], opp);
      for (int c = 0; c < kChannels; ++c) {
        x[c].push_back(view.mean[c][i]);
        y[c].push_back(opp[c]);
      }
    }
  }
  if (x[0].size() < kMinFitPixels) return p;
  for (int c = 0; c < kChannels; ++c) {
    std::vector<char> use(x[c].size(), 1);
    Line l = least_squares(x[c], y[c], use);
    // Once more on the pixels that agree with the first fit (a changed object is an outlier).
    std::vector<float> residual(x[c].size());
    for (std::size_t i = 0; i < x[c].size(); ++i) residual[i] = std::abs(y[c][i] - (l.gain * x[c][i] + l.offset));
    std::vector<float> sorted = residual;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const float sigma = std::max(1.4826f * sorted[sorted.size() / 2], 2.0f / 255.0f);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < use.size(); ++i) kept += (use[i] = residual[i] <= 2.5f * sigma);
    if (kept >= kMinFitPixels) l = least_squares(x[c], y[c], use);
    if (!(l.gain >= kMinGain && l.gain <= kMaxGain) || !std::isfinite(l.offset)) l = Line{};
    p.gain[c] = l.gain;
    p.offset[c] = l.offset;
    p.pixels = std::max(p.pixels, kept);
  }
  return p;
}

}  // namespace scenewatch::surprise
