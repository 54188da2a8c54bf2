// The refinement leaves out points near depth discontinuities (FitConfig::edge_margin_deg): an
// organized view of an upright can whose depth near its silhouettes is flattened the way the
// Xtion's is in ../shared/data/ycb (frame 1, row 350: the last 13 pixels before the invalid band
// all read 908 mm): the pixels within `plateau_px` of an edge repeat the depth of the first pixel
// further in, and their points lie on their own rays at that depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "scenewatch/ontology/fit.h"

namespace scenewatch::ontology {
namespace {

constexpr int kWidth = 160, kHeight = 200;
constexpr double kF = 1066.0, kCx = 80.0, kCy = 100.0;  // YCB-Video's focal length
constexpr double kRadius = 0.033, kDistance = 0.9, kHalfHeight = 0.05;

// Depth (z) of the can at pixel (u, v); NaN off it (the invalid band a sensor leaves there).
double can_depth(int u, int v) {
  const double dx = (u - kCx) / kF, dy = (v - kCy) / kF;
  // (t dx)^2 + (t - d)^2 = r^2: the nearer root.
  const double a = dx * dx + 1, b = -2 * kDistance, c = kDistance * kDistance - kRadius * kRadius;
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return std::numeric_limits<double>::quiet_NaN();
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  return std::abs(t * dy) <= kHalfHeight ? t : std::numeric_limits<double>::quiet_NaN();
}

// The view, each row's outer `plateau_px` pixels on each side at the depth of the next pixel in.
Cloud flattened_view(int plateau_px, std::vector<int>& indices) {
  Cloud cloud;
  cloud.width = kWidth;
  cloud.height = kHeight;
  cloud.points.resize(static_cast<std::size_t>(kWidth * kHeight));
  for (auto& p : cloud.points) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < kHeight; ++v) {
    int first = -1, last = -1;  // the can's run of valid pixels in this row
    for (int u = 0; u < kWidth; ++u) {
      if (std::isnan(can_depth(u, v))) continue;
      if (first < 0) first = u;
      last = u;
    }
    if (first < 0 || last - first < 2 * plateau_px + 2) continue;
    for (int u = first; u <= last; ++u) {
      const int source = std::clamp(u, first + plateau_px, last - plateau_px);
      const double z = can_depth(source, v);
      cloud.points[static_cast<std::size_t>(v * kWidth + u)].getVector3fMap() =
          Eigen::Vector3d((u - kCx) / kF * z, (v - kCy) / kF * z, z).cast<float>();
      indices.push_back(v * kWidth + u);
    }
  }
  return cloud;
}

double fitted_radius(const Cloud& cloud, const std::vector<int>& indices, double margin_deg) {
  FitConfig config;
  config.edge_margin_deg = margin_deg;
  const auto fit = fit_object(cloud, indices, config, Eigen::Vector3d(0, -1, 0));
  EXPECT_TRUE(fit.ok() && fit->cylinder);
  return fit.ok() && fit->cylinder ? fit->cylinder->radius_m : 0.0;
}

TEST(DepthEdgeFitTest, FlattenedSilhouettesWidenTheCanUnlessLeftOut) {
  std::vector<int> exact_indices, flat_indices;
  const Cloud exact = flattened_view(0, exact_indices);
  const FitConfig defaults;  // 0.2 degrees: 4 pixels at this focal length
  const int plateau_px = static_cast<int>(std::lround(defaults.edge_margin_deg * M_PI / 180.0 * kF));
  ASSERT_EQ(plateau_px, 4);
  const Cloud flat = flattened_view(plateau_px, flat_indices);
  const double exact_r = fitted_radius(exact, exact_indices, defaults.edge_margin_deg);
  const double flat_r = fitted_radius(flat, flat_indices, defaults.edge_margin_deg);
  const double flat_r_all = fitted_radius(flat, flat_indices, 0);
  std::printf("radius: exact view %.2f mm, flattened %.2f mm (%.2f mm without the edge margin), true %.1f mm\n",
              exact_r * 1000, flat_r * 1000, flat_r_all * 1000, kRadius * 1000);
  // Measured: 33.00, 33.00 and 34.86 mm.
  EXPECT_NEAR(exact_r, kRadius, 0.0002);
  EXPECT_NEAR(flat_r, kRadius, 0.0002);
  EXPECT_GT(flat_r_all - kRadius, 0.0015) << "the flattening no longer widens the can: the test shows nothing";
}

}  // namespace
}  // namespace scenewatch::ontology
