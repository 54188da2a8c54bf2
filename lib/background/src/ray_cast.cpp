#include "ray_cast.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch::background {

using octomap::OcTreeKey;

namespace {
// One ray's walk. The three axes are separate variables, not arrays indexed by the axis that
// steps: the compiler then keeps them in registers.
class RayWalk {
 public:
  RayWalk(const octomap::ColorOcTree& tree, const octomap::point3d& from, const OcTreeKey& key_from, const octomap::point3d& to)
      : key_(key_from) {
    octomap::point3d direction = to - from;
    length_ = static_cast<float>(direction.norm());
    direction /= length_;
    const double res = tree.getResolution();
    double t_max[3], t_delta[3];
    for (unsigned i = 0; i < 3; ++i) {
      step_[i] = direction(i) > 0.0 ? 1 : (direction(i) < 0.0 ? -1 : 0);
      if (step_[i] != 0) {
        double border = tree.keyToCoord(key_from[i]);
        border += static_cast<float>(step_[i] * res * 0.5);
        t_max[i] = (border - from(i)) / direction(i);
        t_delta[i] = res / std::fabs(direction(i));
      } else {
        t_max[i] = t_delta[i] = std::numeric_limits<double>::max();
      }
    }
    tx_ = t_max[0], ty_ = t_max[1], tz_ = t_max[2];
    dx_ = t_delta[0], dy_ = t_delta[1], dz_ = t_delta[2];
  }
  /// Steps into the next voxel; false once the walk has passed the far end.
  bool next() {
    // The axis whose border comes first; ties go as in computeRayKeys (z, then y, over x).
    if (tx_ < ty_) {
      if (tx_ < tz_) step(0, tx_, dx_);
      else step(2, tz_, dz_);
    } else {
      if (ty_ < tz_) step(1, ty_, dy_);
      else step(2, tz_, dz_);
    }
    return std::min(std::min(tx_, ty_), tz_) <= length_;
  }
  const OcTreeKey& key() const { return key_; }

 private:
  void step(unsigned axis, double& t, double delta) {
    key_[axis] = static_cast<octomap::key_type>(key_[axis] + step_[axis]);
    t += delta;
  }

  OcTreeKey key_;
  float length_ = 0.0f;
  int step_[3];
  double tx_, ty_, tz_, dx_, dy_, dz_;
};
}  // namespace

void cast_ray(const octomap::ColorOcTree& tree, const octomap::point3d& origin, const OcTreeKey& key_origin,
              const octomap::point3d& end, const OcTreeKey& key_end, RaySet& rays) {
  if (key_origin == key_end) return;
  RaySet::FreeWriter out(rays);
  out.test_and_set(key_origin);
  RayWalk walk(tree, origin, key_origin, end);
  while (true) {
    const bool inside = walk.next();
    if (walk.key() == key_end || !inside) return;
    out.test_and_set(walk.key());
  }
}

void cast_ray_back(const octomap::ColorOcTree& tree, const octomap::point3d& sensor, const OcTreeKey& key_sensor,
                   const octomap::point3d& end, const OcTreeKey& key_end, int stop_after, RaySet& rays) {
  if (key_sensor == key_end) return;
  RaySet::FreeWriter out(rays);
  RayWalk walk(tree, end, key_end, sensor);
  int repeated = 0;
  while (walk.next()) {

    if (out.test_and_set(walk.key())) {
      if (++repeated >= stop_after) return;
    } else {
      repeated = 0;
    }
    if (walk.key() == key_sensor) return;
  }
  out.test_and_set(key_sensor);
}

}  // namespace scenewatch::background
