// The cut between levels of stacked objects (segmentation/src/terrace_split.cpp) on synthetic
// organized views: a sensor at the origin looks along +z at a table 1 m away; an object's top is
// drawn as a height field above it, one pixel per 2 mm.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "terrace_split.h"

namespace scenewatch::segmentation {
namespace {

constexpr double kTable = 1.0;   // the table's depth (m)
constexpr double kPixel = 0.002;  // spacing on the table (m)
constexpr int kSize = 120;        // pixels each way (0.24 m)

// An organized view whose pixel (u, v) shows the height field's point above (u, v) on the table,
// or nothing where `height` returns NaN; `part` collects the pixels shown.
Cloud height_field(const std::function<double(double, double)>& height, std::vector<int>& part) {
  Cloud cloud;
  cloud.width = kSize, cloud.height = kSize, cloud.is_dense = false;
  cloud.points.resize(static_cast<std::size_t>(kSize) * kSize);
  for (int v = 0; v < kSize; ++v)
    for (int u = 0; u < kSize; ++u) {
      PointT& p = cloud.points[static_cast<std::size_t>(v) * kSize + u];
      const double x = u * kPixel, y = v * kPixel, h = height(x, y);
      if (std::isnan(h)) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      p.x = static_cast<float>(x), p.y = static_cast<float>(y), p.z = static_cast<float>(kTable - h);
      part.push_back(v * kSize + u);
    }
  return cloud;
}

// The table's plane, n . p + d = 0 with n towards the sensor: height = 1 - z.
const Eigen::Vector3d kUp(0, 0, -1);
constexpr double kD = kTable;

double nan() { return std::numeric_limits<double>::quiet_NaN(); }

// A leaning lid, tilted 5.7 degrees, seen in two pieces around something that hides its middle:
// a wide face and a 24 mm strip beyond, bevelled across its width (its own plane rolls 12 degrees
// against the lid's). The strip's plane, extended over the wide face, misses it by more than the
// noise; the wide face's plane passes through the strip. One surface: no cut.
TEST(TerraceSplit, ALidInAWidePieceAndABevelledStripIsOneLevel) {
  const auto lid = [](double x, double y) {
    const double h = 0.08 + 0.10 * x;
    if (x < 0.08 && y < 0.20) return h;                                    // the wide face
    if (x >= 0.17 && x < 0.23 && y < 0.024) return h + 0.22 * (y - 0.012);  // the strip
    return nan();
  };
  std::vector<int> part;
  const Cloud cloud = height_field(lid, part);
  const auto pieces = split_at_terraces(cloud, part, kUp, kD, TerraceParams{});
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].size(), part.size());
}

// The same wide face with a second face 2 cm above it, parallel: a book on a book. Two levels,
// cut apart, every pixel kept.
TEST(TerraceSplit, ParallelFacesTwoCentimetresApartAreCut) {
  const auto stack = [](double x, double y) {
    if (x < 0.10 && y < 0.10) return 0.08;
    if (x >= 0.14 && x < 0.19 && y < 0.06) return 0.10;
    return nan();
  };
  std::vector<int> part;
  const Cloud cloud = height_field(stack, part);
  const auto pieces = split_at_terraces(cloud, part, kUp, kD, TerraceParams{});
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].size() + pieces[1].size(), part.size());
  EXPECT_EQ(std::min(pieces[0].size(), pieces[1].size()), 25u * 30u);  // the upper face's pixels
}

}  // namespace
}  // namespace scenewatch::segmentation
