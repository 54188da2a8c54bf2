#include "through_image.h"

namespace scenewatch::segmentation {

Segmentation to_cloud_indices(const Cloud& cloud, const ImageGrid& grid, Segmentation seg, double tolerance_m) {
  const std::size_t pixels = grid.point.size();
  std::vector<int> object_of(pixels, -1), plane_of(pixels, -1);
  for (std::size_t o = 0; o < seg.objects.size(); ++o) {
    for (int px : seg.objects[o].indices) object_of[px] = static_cast<int>(o);
    seg.objects[o].indices.clear();
  }
  for (std::size_t p = 0; p < seg.planes.size(); ++p) {
    for (int px : seg.planes[p].indices) plane_of[px] = static_cast<int>(p);
    seg.planes[p].indices.clear();
  }
  const float tol2 = static_cast<float>(tolerance_m * tolerance_m);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int px = grid.pixel[i];
    if (px < 0) continue;
    const int standing = grid.point[px];
    if (standing != static_cast<int>(i) &&
        (cloud[i].getVector3fMap() - cloud[static_cast<std::size_t>(standing)].getVector3fMap()).squaredNorm() > tol2)
      continue;
    if (object_of[px] >= 0) seg.objects[object_of[px]].indices.push_back(static_cast<int>(i));
    if (plane_of[px] >= 0) seg.planes[plane_of[px]].indices.push_back(static_cast<int>(i));
  }
  for (auto& o : seg.objects) o.point_count = o.indices.size();
  for (auto& p : seg.planes) p.inlier_count = p.indices.size();
  return seg;
}

}  // namespace scenewatch::segmentation
