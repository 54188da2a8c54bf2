#include "scenewatch/core/depth_validity.h"

#include <algorithm>
#include <cmath>

namespace scenewatch {
namespace {

// tan(75 degrees): the steepest incidence at which a surface is still taken as one surface.
constexpr double kTanSteepest = 3.7320508;

// Sets bit b of out[i] for every pixel within `r` (Chebyshev distance) of a pixel with bit b of
// `marked` set, for bits 0 and 1 at once: a square dilation, rows then columns, each a running
// count per bit over a window of 2 r + 1.
std::vector<std::uint8_t> dilate_two(const std::vector<std::uint8_t>& marked, int w, int h, int r) {
  if (r <= 0) return marked;
  std::vector<std::uint8_t> rows(marked.size(), 0), out(marked.size(), 0);
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* in = &marked[static_cast<std::size_t>(v) * w];
    std::uint8_t* o = &rows[static_cast<std::size_t>(v) * w];
    int count0 = 0, count1 = 0;
    for (int u = 0; u < std::min(r, w); ++u) count0 += in[u] & 1, count1 += in[u] >> 1;
    for (int u = 0; u < w; ++u) {
      if (u + r < w) count0 += in[u + r] & 1, count1 += in[u + r] >> 1;
      if (u - r - 1 >= 0) count0 -= in[u - r - 1] & 1, count1 -= in[u - r - 1] >> 1;
      o[u] = static_cast<std::uint8_t>((count0 > 0) | ((count1 > 0) << 1));
    }
  }
  std::vector<int> count0(static_cast<std::size_t>(w), 0), count1(static_cast<std::size_t>(w), 0);
  const auto add_row = [&](int v, int sign) {
    const std::uint8_t* row = &rows[static_cast<std::size_t>(v) * w];
    for (int u = 0; u < w; ++u) count0[u] += sign * (row[u] & 1), count1[u] += sign * (row[u] >> 1);
  };
  for (int v = 0; v < std::min(r, h); ++v) add_row(v, 1);
  for (int v = 0; v < h; ++v) {
    if (v + r < h) add_row(v + r, 1);
    if (v - r - 1 >= 0) add_row(v - r - 1, -1);
    std::uint8_t* o = &out[static_cast<std::size_t>(v) * w];
    for (int u = 0; u < w; ++u) o[u] = static_cast<std::uint8_t>((count0[u] > 0) | ((count1[u] > 0) << 1));
  }
  return out;
}

}  // namespace

double depth_edge_step_m(const SensorModel& sensor, double z, double focal_px, double sigma_factor) {
  return sigma_factor * std::sqrt(2.0) * sensor.sigma_z(z) + z * kTanSteepest / focal_px;
}

DepthValidity depth_validity(const std::vector<float>& z, int w, int h, double focal_px, const SensorModel& sensor,
                             double sigma_factor) {
  DepthValidity out;
  out.width = w;
  out.height = h;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  out.bits.assign(n, 0);
  if (w <= 0 || h <= 0 || z.size() != n) return out;
  // Bit 0: a depth edge, bit 1: a hole. Both sides of a step are marked; the nearer side's noise
  // sets the bound (each pixel's bound is computed once, and a pair takes its nearer pixel's).
  constexpr std::uint8_t kEdge = 1, kHole = 2;
  std::vector<std::uint8_t> marks(n, 0);
  std::vector<double> step(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (z[i] > 0) step[i] = depth_edge_step_m(sensor, z[i], focal_px, sigma_factor);  // NaN is no depth
  }
  auto step_between = [&](std::size_t a, std::size_t b) {
    if (!(z[a] > 0) || !(z[b] > 0)) return false;
    return std::abs(z[a] - z[b]) > step[z[b] < z[a] ? b : a];
  };
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (!(z[i] > 0)) marks[i] |= kHole;
      if (u + 1 < w && step_between(i, i + 1)) marks[i] |= kEdge, marks[i + 1] |= kEdge;
      if (v + 1 < h && step_between(i, i + w)) marks[i] |= kEdge, marks[i + w] |= kEdge;
    }
  const std::vector<std::uint8_t> near = dilate_two(marks, w, h, sensor.edge_band_px(sigma_factor));
  const int b = sensor.border_px;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      std::uint8_t bits = 0;
      if (z[i] > 0 && sensor.in_range(z[i])) bits |= DepthValidity::kInRange;
      if (u >= b && v >= b && u < w - b && v < h - b) bits |= DepthValidity::kInterior;
      if (!(near[i] & kEdge)) bits |= DepthValidity::kOffEdge;
      if (!(near[i] & kHole)) bits |= DepthValidity::kOffHole;
      out.bits[i] = bits;
      out.valid += (bits & DepthValidity::kInRange) ? 1 : 0;
      out.trusted += bits == DepthValidity::kTrusted ? 1 : 0;
    }
  return out;
}

}  // namespace scenewatch
