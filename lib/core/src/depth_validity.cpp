#include "scenewatch/core/depth_validity.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch {
namespace {

// tan(75 degrees): the steepest incidence at which a surface is still taken as one surface.
constexpr double kTanSteepest = 3.7320508;
// 1 - 2^-24, the float just below 1.
constexpr float kJustBelowOne = 1.0f - 1.0f / 16777216.0f;

// Sets in out[i] every bit that is set in `marked` at some pixel within `r` of i (Chebyshev
// distance): a square dilation of each bit at once, as the OR over a window of 2 r + 1, rows then
// columns. OR keeps the bits apart, and with r a few pixels the plain window is cheaper than
// running counts: it has no branch and no carried state, so it runs on whole vectors of bytes.
std::vector<std::uint8_t> dilate_bits(const std::vector<std::uint8_t>& marked, int w, int h, int r) {
  if (r <= 0) return marked;
  const std::size_t width = static_cast<std::size_t>(w);
  std::vector<std::uint8_t> padded(width + 2 * static_cast<std::size_t>(r), 0), rows(marked.size()), out(marked.size());
  for (int v = 0; v < h; ++v) {
    std::copy_n(&marked[static_cast<std::size_t>(v) * width], width, padded.begin() + r);
    std::uint8_t* o = &rows[static_cast<std::size_t>(v) * width];
    std::copy_n(padded.begin(), width, o);
    for (int k = 1; k <= 2 * r; ++k) {
      const std::uint8_t* in = &padded[static_cast<std::size_t>(k)];
      for (std::size_t u = 0; u < width; ++u) o[u] |= in[u];
    }
  }
  for (int v = 0; v < h; ++v) {
    std::uint8_t* o = &out[static_cast<std::size_t>(v) * width];
    const int first = std::max(0, v - r), last = std::min(h - 1, v + r);
    std::copy_n(&rows[static_cast<std::size_t>(first) * width], width, o);
    for (int k = first + 1; k <= last; ++k) {
      const std::uint8_t* in = &rows[static_cast<std::size_t>(k) * width];
      for (std::size_t u = 0; u < width; ++u) o[u] |= in[u];
    }
  }
  return out;
}

// depth_edge_step_m with its constants taken out of the sensor model (`along`: sigma_factor
// sqrt(2)), so that a loop over pixels holds them in registers; the same arithmetic, in the same
// order (sigma_z inlined).
inline double edge_step(double z, double along, double offset, double base, double quad, double focal_px) {
  const double d = z - offset;
  return along * (base + quad * d * d) + z * kTanSteepest / focal_px;
}

}  // namespace

double depth_edge_step_m(const SensorModel& sensor, double z, double focal_px, double sigma_factor) {
  return edge_step(z, sigma_factor * std::sqrt(2.0), sensor.axial_offset_m, sensor.axial_base_m, sensor.axial_quad_per_m, focal_px);
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
  // Every loop below is a row of selects without branches over plain pointers, so that it runs
  // on vectors.
  constexpr std::uint8_t kEdge = 1, kHole = 2;
  static_assert(DepthValidity::kOffEdge == kEdge << 2 && DepthValidity::kOffHole == kHole << 2, "off bits are marks << 2");
  const std::size_t width = static_cast<std::size_t>(w);
  std::vector<std::uint8_t> marks(n);
  std::vector<float> steps(n);
  const float* __restrict depth = z.data();
  float* __restrict step = steps.data();
  std::uint8_t* __restrict mark = marks.data();
  // The working range as floats: a float depth lies in [min, max] exactly when it lies in
  // [lo, hi], the nearest floats inside.
  float lo = static_cast<float>(sensor.min_range_m), hi = static_cast<float>(sensor.max_range_m);
  if (static_cast<double>(lo) < sensor.min_range_m) lo = std::nextafter(lo, HUGE_VALF);
  if (static_cast<double>(hi) > sensor.max_range_m) hi = std::nextafter(hi, -HUGE_VALF);
  lo = std::max(lo, std::numeric_limits<float>::denorm_min());  // no depth (0) is never in range
  std::uint8_t* __restrict bits_out = out.bits.data();
  // Each pixel's bound as the float just below it: for a float gap g and a double bound s,
  // g > s exactly when g > s rounded down to a float, so the comparisons below run in floats.
  const double along = sigma_factor * std::sqrt(2.0), offset = sensor.axial_offset_m, base = sensor.axial_base_m,
               quad = sensor.axial_quad_per_m;
  for (std::size_t i = 0; i < n; ++i) {  // NaN is no depth: z > 0 is false for it
    const double s = edge_step(depth[i], along, offset, base, quad, focal_px);
    // s is a normal positive float's worth, and x (1 - 2^-24), rounded, is the float just below
    // a normal positive x.
    const float up = static_cast<float>(s);
    const float below = static_cast<double>(up) > s ? up * kJustBelowOne : up;
    step[i] = depth[i] > 0 ? below : 0.0f;
    mark[i] = depth[i] > 0 ? 0 : kHole;
    bits_out[i] = (depth[i] >= lo) & (depth[i] <= hi) ? DepthValidity::kInRange : 0;
  }
  // Whether a step lies between pixels a and b: both have a depth, and they differ by more than
  // the nearer one's bound.
  const auto step_between = [&](std::size_t a, std::size_t b) -> std::uint8_t {
    const float za = depth[a], zb = depth[b], sa = step[a], sb = step[b];
    const float bound = zb < za ? sb : sa;
    return static_cast<std::uint8_t>((za > 0) & (zb > 0) & (std::abs(za - zb) > bound));
  };
  std::vector<std::uint8_t> steps_across(width);  // the step right of each pixel of a row, or below it
  std::uint8_t* __restrict across = steps_across.data();
  for (std::size_t v = 0; v < static_cast<std::size_t>(h); ++v) {
    const std::size_t i0 = v * width;
    std::uint8_t* __restrict row = mark + i0;
    for (std::size_t u = 0; u + 1 < width; ++u) across[u] = step_between(i0 + u, i0 + u + 1);
    for (std::size_t u = 0; u + 1 < width; ++u) row[u] |= across[u];
    for (std::size_t u = 1; u < width; ++u) row[u] |= across[u - 1];
    if (v + 1 == static_cast<std::size_t>(h)) break;
    std::uint8_t* __restrict next = row + width;
    for (std::size_t u = 0; u < width; ++u) across[u] = step_between(i0 + u, i0 + u + width);
    for (std::size_t u = 0; u < width; ++u) row[u] |= across[u];
    for (std::size_t u = 0; u < width; ++u) next[u] |= across[u];
  }
  const std::vector<std::uint8_t> near_marks = dilate_bits(marks, w, h, sensor.edge_band_px(sigma_factor));
  const std::uint8_t* __restrict near = near_marks.data();
  const std::size_t b = static_cast<std::size_t>(std::max(sensor.border_px, 0));
  // The image's interior, as the bits of one row: border rows get none of it.
  std::vector<std::uint8_t> interior_row(width, 0);
  for (std::size_t u = b; u + b < width; ++u) interior_row[u] = DepthValidity::kInterior;
  const std::uint8_t* __restrict interior = interior_row.data();
  std::size_t valid = 0, trusted = 0;
  for (std::size_t v = 0; v < static_cast<std::size_t>(h); ++v) {
    std::uint8_t* __restrict row = bits_out + v * width;
    const std::uint8_t* __restrict near_row = near + v * width;
    const std::uint8_t inside = v >= b && v + b < static_cast<std::size_t>(h) ? 0xff : 0;
    for (std::size_t u = 0; u < width; ++u)
      row[u] = static_cast<std::uint8_t>(row[u] | (interior[u] & inside) | ((~near_row[u] & (kEdge | kHole)) << 2));
    std::uint32_t row_valid = 0, row_trusted = 0;
    for (std::size_t u = 0; u < width; ++u) row_valid += row[u] & DepthValidity::kInRange;
    for (std::size_t u = 0; u < width; ++u) row_trusted += row[u] == DepthValidity::kTrusted;
    valid += row_valid;
    trusted += row_trusted;
  }
  out.valid = valid;
  out.trusted = trusted;
  return out;
}

}  // namespace scenewatch
