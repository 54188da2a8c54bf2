// The frame on a coarser grid: sampling, the border test and small helpers.
#include "frame_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch::foreground {
namespace {

/// An empty band along the image's side at most this wide (pixels) counts as the border.
constexpr int kMaxEmptyBorderPx = 48;

}  // namespace

bool Grid::on_border(int cell, int margin) const {
  const int u = u_full(cell), v = v_full(cell);
  if (u <= margin || v <= margin || u >= full_w - 1 - margin || v >= full_h - 1 - margin) return true;
  const int gu = cell % w, gv = cell / w;
  const auto near = [&](int first, int here, bool from_start, int extent) {
    if (first < 0) return false;
    const int edge_px = from_start ? first * step : (extent - 1 - first) * step;
    const int here_px = from_start ? here * step : (extent - 1 - here) * step;
    return edge_px <= kMaxEmptyBorderPx && here_px <= edge_px + margin;
  };
  return near(first_left[gv], gu, true, w) || near(first_right[gv], gu, false, w) ||
         near(first_top[gu], gv, true, h) || near(first_bottom[gu], gv, false, h);
}

Grid sample_grid(const Cloud& cloud, int step) {
  Grid g;
  g.full_w = static_cast<int>(cloud.width);
  g.full_h = static_cast<int>(cloud.height);
  g.step = step;
  g.w = (g.full_w + step - 1) / step;
  g.h = (g.full_h + step - 1) / step;
  const std::size_t n = static_cast<std::size_t>(g.w) * g.h;
  g.p.assign(n, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  g.valid.assign(n, 0);
  g.rgb.assign(n * 3, 0);
  g.src.assign(n, 0);
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      const int cell = gv * g.w + gu;
      const int u0 = gu * step, v0 = gv * step;
      int chosen = v0 * g.full_w + u0;
      for (int dv = 0; dv < step && !g.valid[cell]; ++dv) {
        for (int du = 0; du < step; ++du) {
          const int u = u0 + du, v = v0 + dv;
          if (u >= g.full_w || v >= g.full_h) continue;
          const int i = v * g.full_w + u;
          if (is_valid(cloud.points[i]) && cloud.points[i].z > 0) {
            chosen = i;
            g.valid[cell] = 1;
            break;
          }
        }
      }
      const PointT& pt = cloud.points[chosen];
      g.src[cell] = chosen;
      if (g.valid[cell]) g.p[cell] = pt.getVector3fMap();
      g.rgb[3 * cell] = pt.r;
      g.rgb[3 * cell + 1] = pt.g;
      g.rgb[3 * cell + 2] = pt.b;
    }
  }
  g.first_left.assign(g.h, -1), g.first_right.assign(g.h, -1), g.first_top.assign(g.w, -1), g.first_bottom.assign(g.w, -1);
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      if (!g.valid[gv * g.w + gu]) continue;
      if (g.first_left[gv] < 0) g.first_left[gv] = gu;
      g.first_right[gv] = gu;
      if (g.first_top[gu] < 0) g.first_top[gu] = gv;
      g.first_bottom[gu] = gv;
    }
  }
  return g;
}

double estimate_focal_px(const Grid& g) {
  double fs[2] = {0, 0};
  for (int axis = 0; axis < 2; ++axis) {
    double sa = 0, sb = 0, saa = 0, sab = 0;
    std::size_t n = 0;
    for (std::size_t cell = 0; cell < g.p.size(); cell += 7) {
      if (!g.valid[cell]) continue;
      const Eigen::Vector3f& q = g.p[cell];
      const double a = (axis == 0 ? q.x() : q.y()) / q.z();
      const double b = axis == 0 ? g.u_full(static_cast<int>(cell)) : g.v_full(static_cast<int>(cell));
      sa += a, sb += b, saa += a * a, sab += a * b;
      ++n;
    }
    const double den = n * saa - sa * sa;
    if (n >= 10 && den > 1e-12) fs[axis] = (n * sab - sa * sb) / den;
  }
  const double f = std::sqrt(std::max(0.0, fs[0] * fs[1]));
  // Fallback: a VGA Kinect-class camera's focal length, scaled to the image width.
  return std::isfinite(f) && f > 1 ? f : 525.0 * g.full_w / 640.0;
}

Eigen::Vector3d centroid_of(const Grid& g, const std::vector<int>& cells) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int i : cells) c += g.p[i].cast<double>();
  return cells.empty() ? c : Eigen::Vector3d(c / static_cast<double>(cells.size()));
}

double distance_to_border(const Grid& g, const std::vector<int>& cells) {
  double u = 0, v = 0;
  for (int i : cells) u += g.u_full(i), v += g.v_full(i);
  u /= std::max<std::size_t>(1, cells.size()), v /= std::max<std::size_t>(1, cells.size());
  return std::min({u, v, g.full_w - 1 - u, g.full_h - 1 - v});
}

}  // namespace scenewatch::foreground
