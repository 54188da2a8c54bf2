#include "scenewatch/core/depth_validity.h"

#include <algorithm>
#include <cmath>

namespace scenewatch {
namespace {

// tan(75 degrees): the steepest incidence at which a surface is still taken as one surface.
constexpr double kTanSteepest = 3.7320508;

// Sets every pixel within `r` (Chebyshev distance) of a marked one: a square dilation, rows then
// columns, each a running count over a window of 2 r + 1.
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& marked, int w, int h, int r) {
  if (r <= 0) return marked;
  std::vector<std::uint8_t> rows(marked.size(), 0), out(marked.size(), 0);
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* in = &marked[static_cast<std::size_t>(v) * w];
    std::uint8_t* o = &rows[static_cast<std::size_t>(v) * w];
    int count = 0;
    for (int u = 0; u < std::min(r, w); ++u) count += in[u];
    for (int u = 0; u < w; ++u) {
      if (u + r < w) count += in[u + r];
      if (u - r - 1 >= 0) count -= in[u - r - 1];
      o[u] = count > 0;
    }
  }
  std::vector<int> count(static_cast<std::size_t>(w), 0);
  for (int v = 0; v < std::min(r, h); ++v)
    for (int u = 0; u < w; ++u) count[u] += rows[static_cast<std::size_t>(v) * w + u];
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (v + r < h) count[u] += rows[static_cast<std::size_t>(v + r) * w + u];
      if (v - r - 1 >= 0) count[u] -= rows[static_cast<std::size_t>(v - r - 1) * w + u];
      out[static_cast<std::size_t>(v) * w + u] = count[u] > 0;
    }
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
  std::vector<std::uint8_t> edge(n, 0), hole(n, 0);
  // Both sides of a step are marked (the nearer side's noise sets the bound).
  auto step_between = [&](std::size_t a, std::size_t b) {
    if (!(z[a] > 0) || !(z[b] > 0)) return false;  // NaN too
    const double near = std::min(z[a], z[b]);
    return std::abs(z[a] - z[b]) > depth_edge_step_m(sensor, near, focal_px, sigma_factor);
  };
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      hole[i] = !(z[i] > 0);
      if (u + 1 < w && step_between(i, i + 1)) edge[i] = edge[i + 1] = 1;
      if (v + 1 < h && step_between(i, i + w)) edge[i] = edge[i + w] = 1;
    }
  const int band = sensor.edge_band_px(sigma_factor);
  const std::vector<std::uint8_t> near_edge = dilate(edge, w, h, band);
  const std::vector<std::uint8_t> near_hole = dilate(hole, w, h, band);
  const int b = sensor.border_px;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      std::uint8_t bits = 0;
      if (z[i] > 0 && sensor.in_range(z[i])) bits |= DepthValidity::kInRange;
      if (u >= b && v >= b && u < w - b && v < h - b) bits |= DepthValidity::kInterior;
      if (!near_edge[i]) bits |= DepthValidity::kOffEdge;
      if (!near_hole[i]) bits |= DepthValidity::kOffHole;
      out.bits[i] = bits;
      out.valid += (bits & DepthValidity::kInRange) ? 1 : 0;
      out.trusted += bits == DepthValidity::kTrusted ? 1 : 0;
    }
  return out;
}

}  // namespace scenewatch
