// The frame's points near a place (frame_crop.h): only the pixels whose points can lie in the
// sphere are visited.
#include "frame_crop.h"

#include <algorithm>
#include <cmath>

#include "object_points.h"
#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {
namespace {

constexpr double kSupportBandM = 0.012;  // frame points this close to a supporting plane are the plane's

// The pixels whose points can lie within `radius` of `centre` (camera frame): the image box of
// the sphere's bounding box; the whole image when the camera is unknown or inside the sphere.
struct PixelWindow {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;  // [u0, u1) x [v0, v1)
};

PixelWindow pixel_window(const FrameView& f, const Eigen::Vector3f& centre, double radius) {
  const Cloud& cloud = *f.cloud;
  PixelWindow w{0, 0, static_cast<int>(cloud.width), static_cast<int>(cloud.height)};
  const double near = centre.z() - radius, far = centre.z() + radius;
  if (!f.K || cloud.height <= 1 || near <= 0.01) return w;
  auto span = [&](double c, double focal, double principal, int size, int& lo, int& hi) {
    const double a = (c - radius) / near, b = (c - radius) / far, d = (c + radius) / near, e = (c + radius) / far;
    lo = std::max(0, static_cast<int>(std::floor(principal + focal * std::min({a, b, d, e}))) - 1);
    hi = std::min(size, static_cast<int>(std::ceil(principal + focal * std::max({a, b, d, e}))) + 2);
  };
  span(centre.x(), f.K->fx, f.K->cx, w.u1, w.u0, w.u1);
  span(centre.y(), f.K->fy, f.K->cy, w.v1, w.v0, w.v1);
  return w;
}

// Adds pixel i to the crop when its point lies within the sphere and is neither an agent's nor
// on a supporting plane.
void add_to_crop(const FrameView& f, std::size_t i, const Eigen::Vector3f& centre_cam, float r2,
                 const std::vector<const Plane*>& supports, VoxelSet& kept, Crop& c) {
  const PointT& p = f.cloud->points[i];
  if (!is_valid(p) || (p.getVector3fMap() - centre_cam).squaredNorm() > r2) return;
  if (f.hands && f.hands->is_agent(static_cast<int>(i))) return;
  const Eigen::Vector3d w = world(p, f.T_world_camera);
  for (const Plane* pl : supports)
    if (std::abs(pl->signed_distance(w)) < kSupportBandM) return;
  c.pixels.push_back(static_cast<int>(i));
  c.points.push_back(w);
  if (!kept.insert(w)) return;
  PointT q = p;
  q.getVector3fMap() = w.cast<float>();
  c.target.push_back(q);
}

}  // namespace

Crop crop(const FrameView& f, const Eigen::Vector3d& centre_world, double radius, double voxel) {
  Crop c;
  const Pose& T = f.T_world_camera;
  const Eigen::Vector3f centre_cam = (T.inverse() * centre_world).cast<float>();
  const float r2 = static_cast<float>(radius * radius);
  std::vector<const Plane*> supports;
  if (f.planes) {
    for (const auto& pl : *f.planes) {
      if (pl.normal.dot(f.up_world) > 0.9) supports.push_back(&pl);
    }
  }
  VoxelSet kept(voxel);
  const Cloud& cloud = *f.cloud;
  const PixelWindow w = pixel_window(f, centre_cam, radius);
  const std::size_t area = static_cast<std::size_t>(std::max(0, w.u1 - w.u0)) * static_cast<std::size_t>(std::max(0, w.v1 - w.v0));
  c.pixels.reserve(area / 2);
  c.points.reserve(area / 2);
  for (int v = w.v0; v < w.v1; ++v)
    for (int u = w.u0; u < w.u1; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * cloud.width + static_cast<std::size_t>(u);
      add_to_crop(f, i, centre_cam, r2, supports, kept, c);
    }
  c.target.width = static_cast<std::uint32_t>(c.target.size());
  c.target.height = 1;
  return c;
}

}  // namespace scenewatch::foreground
