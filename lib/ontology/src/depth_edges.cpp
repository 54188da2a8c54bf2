// Depth discontinuities of an organized cloud around one object, and the object's pixels near
// them: an edge map over the object's bounding box (plus the margin), dilated by the margin.
#include "depth_edges.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::ontology::detail {
namespace {

/// Dilates a w x h binary map by `r` pixels along one axis (stride 1: rows, stride w: columns),
/// with a running count over the window: O(w h) whatever r.
void dilate_1d(std::vector<char>& map, int w, int h, int r, bool along_rows) {
  const int lines = along_rows ? h : w, length = along_rows ? w : h;
  const int step = along_rows ? 1 : w, line_step = along_rows ? w : 1;
  std::vector<char> line(static_cast<std::size_t>(length));
  for (int l = 0; l < lines; ++l) {
    const int base = l * line_step;
    for (int i = 0; i < length; ++i) line[static_cast<std::size_t>(i)] = map[static_cast<std::size_t>(base + i * step)];
    int count = 0;  // set pixels in [i - r, i + r]
    for (int i = 0; i < std::min(r, length); ++i) count += line[static_cast<std::size_t>(i)];
    for (int i = 0; i < length; ++i) {
      if (i + r < length) count += line[static_cast<std::size_t>(i + r)];
      if (i - r - 1 >= 0) count -= line[static_cast<std::size_t>(i - r - 1)];
      map[static_cast<std::size_t>(base + i * step)] = count > 0 ? 1 : 0;
    }
  }
}

}  // namespace

double pixel_angle_rad(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& sensor_origin) {
  const int width = static_cast<int>(cloud.width);
  std::vector<double> angles;
  const std::size_t step = std::max<std::size_t>(1, indices.size() / 64);
  for (std::size_t k = 0; k < indices.size(); k += step) {
    const int i = indices[k];
    if ((i + 1) % width == 0) continue;
    const PointT& a = cloud.points[static_cast<std::size_t>(i)];
    const PointT& b = cloud.points[static_cast<std::size_t>(i + 1)];
    if (!is_valid(a) || !is_valid(b)) continue;
    const Eigen::Vector3d ra = (a.getVector3fMap().cast<double>() - sensor_origin).normalized();
    const Eigen::Vector3d rb = (b.getVector3fMap().cast<double>() - sensor_origin).normalized();
    angles.push_back(std::atan2(ra.cross(rb).norm(), ra.dot(rb)));
  }
  if (angles.empty()) return 0.0;
  std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2), angles.end());
  return angles[angles.size() / 2];
}

std::vector<char> near_depth_edge(const Cloud& cloud, const std::vector<int>& indices, double margin_deg, double jump_m,
                                  const Eigen::Vector3d& sensor_origin) {
  std::vector<char> out(indices.size(), 0);
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  if (!(margin_deg > 0) || height <= 1 || indices.empty() ||
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) != cloud.points.size()) {
    return out;
  }
  const double pixel = pixel_angle_rad(cloud, indices, sensor_origin);
  if (!(pixel > 0)) return out;
  const int margin_px = std::min(100, static_cast<int>(std::lround(margin_deg * M_PI / 180.0 / pixel)));
  if (margin_px <= 0) return out;
  int u0 = width, v0 = height, u1 = -1, v1 = -1;
  for (const int i : indices) {
    u0 = std::min(u0, i % width), u1 = std::max(u1, i % width);
    v0 = std::min(v0, i / width), v1 = std::max(v1, i / width);
  }
  // The box around the object, the margin and one pixel more (the neighbour of a jump).
  u0 = std::max(0, u0 - margin_px - 1), v0 = std::max(0, v0 - margin_px - 1);
  u1 = std::min(width - 1, u1 + margin_px + 1), v1 = std::min(height - 1, v1 + margin_px + 1);
  const int w = u1 - u0 + 1, h = v1 - v0 + 1;
  const auto range = [&](int u, int v) {
    const PointT& p = cloud.points[static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u)];
    return is_valid(p) ? (p.getVector3fMap().cast<double>() - sensor_origin).norm() : std::nan("");
  };
  std::vector<char> edge(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  const auto at = [&](int u, int v) -> char& { return edge[static_cast<std::size_t>((v - v0) * w + (u - u0))]; };
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const double z = range(u, v);
      if (std::isnan(z)) {
        at(u, v) = 1;
        continue;
      }
      if (u < u1) {
        const double right = range(u + 1, v);
        if (!std::isnan(right) && std::abs(right - z) > jump_m) at(u, v) = at(u + 1, v) = 1;
      }
      if (v < v1) {
        const double below = range(u, v + 1);
        if (!std::isnan(below) && std::abs(below - z) > jump_m) at(u, v) = at(u, v + 1) = 1;
      }
    }
  }
  dilate_1d(edge, w, h, margin_px, true);
  dilate_1d(edge, w, h, margin_px, false);
  for (std::size_t k = 0; k < indices.size(); ++k) out[k] = at(indices[k] % width, indices[k] / width);
  return out;
}

}  // namespace scenewatch::ontology::detail
