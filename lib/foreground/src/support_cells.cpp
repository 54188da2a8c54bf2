// The hand detector's planes on its grid (support_cells.h): RANSAC on a coarser grid, then each
// fine cell tested against the planes whose patches hold its coarse cell.
#include "support_cells.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace scenewatch::foreground {
namespace {

/// A wall: a plane with at least this fraction of the points off the table and floor.
constexpr double kMinWallFraction = 0.12;

}  // namespace

SupportCells find_support_cells(const Grid& g, float tolerance_m, PlaneMemory* table_memory, PlaneMemory* wall_memory) {
  SupportCells s;
  const std::size_t n = g.p.size();
  SupportPlaneConfig& plane_config = s.plane_config;
  plane_config.tolerance_m = tolerance_m;
  // Planes are found on a coarser grid (every other cell; they are large, and RANSAC's cost is
  // in the points), then a cell lies on one when its coarse cell is in a kept patch and the cell
  // itself is within the tolerance.
  const int cw = (g.w + 1) / 2, ch = (g.h + 1) / 2;
  std::vector<Eigen::Vector3f> coarse_p(static_cast<std::size_t>(cw) * ch);
  std::vector<std::uint8_t> coarse_valid(coarse_p.size(), 0);
  for (int v = 0; v < ch; ++v) {
    for (int u = 0; u < cw; ++u) {
      const std::size_t fine = static_cast<std::size_t>(2 * v) * g.w + 2 * u;
      coarse_p[static_cast<std::size_t>(v) * cw + u] = g.p[fine];
      coarse_valid[static_cast<std::size_t>(v) * cw + u] = g.valid[fine];
    }
  }
  std::vector<std::uint8_t> coarse_table, coarse_wall;
  s.tables = find_support_planes(coarse_p, coarse_valid, cw, ch, plane_config, &coarse_table, table_memory);
  const std::vector<SupportPlane>& planes = s.tables;
  // Then walls: any plane covering a good part of what is left. A person's body is never that
  // large and flat; without this the body grows into a wall it stands close to.
  std::vector<std::uint8_t> rest(coarse_p.size(), 0);
  for (std::size_t c = 0; c < rest.size(); ++c) rest[c] = coarse_valid[c] && !coarse_table[c];
  SupportPlaneConfig wall_config = plane_config;
  wall_config.min_abs_normal_y = 0.0f;
  wall_config.min_fraction = kMinWallFraction;
  const std::vector<SupportPlane> walls = find_support_planes(coarse_p, rest, cw, ch, wall_config, &coarse_wall, wall_memory);
  // Distance to the table or floor, for telling an arm held up from an object lying there.
  std::vector<float>& plane_distance = s.plane_distance;
  plane_distance.assign(n, std::numeric_limits<float>::infinity());
  cv::Mat& on_support = s.on_support;
  on_support = cv::Mat(g.h, g.w, CV_8U, cv::Scalar(0));
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      const std::size_t c = static_cast<std::size_t>(gv) * g.w + gu;
      if (!g.valid[c]) continue;
      for (const SupportPlane& plane : planes) plane_distance[c] = std::min(plane_distance[c], std::abs(plane.distance(g.p[c])));
      const std::size_t coarse = static_cast<std::size_t>(gv / 2) * cw + gu / 2;
      const float tolerance = plane_config.tolerance_at(g.p[c].z());
      bool on = coarse_table[coarse] && plane_distance[c] < tolerance;
      if (!on && coarse_wall[coarse]) {
        for (const SupportPlane& wall : walls) on |= std::abs(wall.distance(g.p[c])) < tolerance;
      }
      on_support.data[c] = on;
    }
  }
  // The person may not enter a band around the planes either: the table's rounded edge is off
  // the plane but part of the table.
  cv::dilate(on_support, s.near_support, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  return s;
}

}  // namespace scenewatch::foreground
