#pragma once
/// The frame on a coarser grid, where the hand detector works: one 3D point and colour per
/// step x step block, with the helpers that walk it. Private to the foreground module.
#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"

namespace scenewatch::foreground {

/// The frame subsampled: one point per step x step block (the block's first valid one).
struct Grid {
  int w = 0, h = 0, step = 1, full_w = 0, full_h = 0;
  std::vector<Eigen::Vector3f> p;  ///< camera frame; NaN where the block has no depth
  std::vector<std::uint8_t> valid;
  std::vector<std::uint8_t> rgb;   ///< w * h * 3
  std::vector<int> src;            ///< index of the sampled pixel in the full frame
  /// Per row and per column, the first cell with depth from each side (-1: none).
  std::vector<int> first_left, first_right, first_top, first_bottom;

  int u_full(int cell) const { return src[cell] % full_w; }
  int v_full(int cell) const { return src[cell] / full_w; }
  /// Within `margin` pixels of the image border, or of where depth begins when the image's edge
  /// has none (a depth image registered to the colour camera has an empty band along its sides).
  bool on_border(int cell, int margin) const;
};

/// Samples an organized cloud (width * height points) on a grid of every step-th pixel.
Grid sample_grid(const Cloud& organized, int step);

/// The focal length in pixels, by least squares on u = f x / z + c over the valid points (the
/// cloud carries no intrinsics); a Kinect-class guess when the cloud gives none.
double estimate_focal_px(const Grid& g);

/// Mean of the cells' points.
Eigen::Vector3d centroid_of(const Grid& g, const std::vector<int>& cells);

/// Pixels from the mean image position of the cells to the nearest image border.
double distance_to_border(const Grid& g, const std::vector<int>& cells);

/// Breadth-first growth over 4-neighbours from seeds: a valid cell joins when accept(cell) and
/// its depth is within depth_jump of the neighbour it is reached from. `mark` gets `id` for
/// joined cells (a fresh id per growth avoids clearing it). Returns the seeds and joined cells.
template <typename Accept>
std::vector<int> grow(const Grid& g, const std::vector<int>& seeds, float depth_jump, std::vector<int>& mark, int id, Accept accept) {
  std::vector<int> out;
  std::deque<int> queue;
  for (int s : seeds) {
    if (mark[s] == id) continue;
    mark[s] = id;
    out.push_back(s);
    queue.push_back(s);
  }
  static constexpr int kDu[4] = {1, -1, 0, 0}, kDv[4] = {0, 0, 1, -1};
  while (!queue.empty()) {
    const int c = queue.front();
    queue.pop_front();
    const int cu = c % g.w, cv = c / g.w;
    for (int k = 0; k < 4; ++k) {
      const int nu = cu + kDu[k], nv = cv + kDv[k];
      if (nu < 0 || nv < 0 || nu >= g.w || nv >= g.h) continue;
      const int n = nv * g.w + nu;
      if (mark[n] == id || !g.valid[n]) continue;
      if (std::abs(g.p[n].z() - g.p[c].z()) >= depth_jump) continue;
      if (!accept(n)) continue;
      mark[n] = id;
      out.push_back(n);
      queue.push_back(n);
    }
  }
  return out;
}

}  // namespace scenewatch::foreground
