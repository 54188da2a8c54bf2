#include "footprint.h"

#include <algorithm>

namespace scenewatch::segmentation {

Footprint footprint(const Cloud& cloud, const std::vector<int>& part, const Eigen::Vector3d& up) {
  Eigen::Vector3d u, v;
  plane_basis(up, u, v);
  Footprint f;
  std::vector<double> heights;
  heights.reserve(part.size());
  f.points.reserve(part.size());
  for (int i : part) {
    const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>();
    f.points.emplace_back(p.dot(u), p.dot(v));
    heights.push_back(p.dot(up));
  }
  f.hull = convex_hull(f.points);
  if (!heights.empty()) {
    // The 5th and 95th percentiles: two selections, not a sort.
    const std::size_t k = heights.size() / 20, n = heights.size();
    std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k), heights.end());
    f.low = heights[k];
    std::nth_element(heights.begin() + static_cast<std::ptrdiff_t>(k), heights.begin() + static_cast<std::ptrdiff_t>(n - 1 - k), heights.end());
    f.high = heights[n - 1 - k];
  }
  return f;
}

double share_inside(const Footprint& a, const Footprint& b) {
  if (a.points.empty()) return 0.0;
  std::size_t in = 0;
  for (const Vec2& p : a.points) in += inside_convex(b.hull, p) ? 1 : 0;
  return static_cast<double>(in) / a.points.size();
}

}  // namespace scenewatch::segmentation
