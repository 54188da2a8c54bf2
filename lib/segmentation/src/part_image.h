#pragma once
// A part of an organized cloud (its point indices) laid out in its bounding box in the image.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

/// The part's pixels in its bounding box: each pixel's local index (into `part`), -1 outside.
struct PartImage {
  int width = 0;  ///< the organized cloud's
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;
  int bw = 0, bh = 0;
  std::vector<int> local;

  PartImage(const Cloud& cloud, const std::vector<int>& part) : width(static_cast<int>(cloud.width)) {
    u0 = width, v0 = static_cast<int>(cloud.height);
    for (int i : part) {
      u0 = std::min(u0, i % width), u1 = std::max(u1, i % width);
      v0 = std::min(v0, i / width), v1 = std::max(v1, i / width);
    }
    bw = u1 - u0 + 1, bh = v1 - v0 + 1;
    local.assign(static_cast<std::size_t>(bw) * bh, -1);
    for (std::size_t k = 0; k < part.size(); ++k) at(part[k] % width, part[k] / width) = static_cast<int>(k);
  }
  int& at(int u, int v) { return local[static_cast<std::size_t>(v - v0) * bw + (u - u0)]; }
  /// The local index at image pixel (u, v), -1 outside the part or its box.
  int find(int u, int v) const {
    return u < u0 || v < v0 || u > u1 || v > v1 ? -1 : local[static_cast<std::size_t>(v - v0) * bw + (u - u0)];
  }
};

}  // namespace scenewatch::segmentation
