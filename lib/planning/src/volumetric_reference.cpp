// ViewScorer's reference walk: the straightforward 3D-DDA (Amanatides & Woo 1987) that visits every
// voxel of the clipped ray and tests each for everything. score() must give the same gains; the
// tests compare the two on many views (tests/planning/volumetric_test.cpp).
#include "scenewatch/planning/volumetric.h"

namespace scenewatch::planning {

namespace {

constexpr std::uint8_t kUnknown = static_cast<std::uint8_t>(background::Occupancy::kUnknown);
constexpr std::uint8_t kOccupied = static_cast<std::uint8_t>(background::Occupancy::kOccupied);

}  // namespace

void ViewScorer::walk_ray_reference(const Eigen::Vector3d& g0, const Eigen::Vector3d& dg, double t_enter, double t_exit,
                                    std::uint32_t stamp, ViewGain& out, RaySums& sums) {
  const long n[3] = {grid_.nx, grid_.ny, grid_.nz};
  const long stride[3] = {1, grid_.nx, static_cast<long>(grid_.nx) * grid_.ny};
  Traversal r = start(g0, dg, t_enter);
  long* const ijk = r.ijk;
  RayState ray;
  ray_unknown_.clear();
  for (;;) {
    ++out.steps;
    const bool in_target = ijk[0] >= lo_[0] && ijk[0] <= hi_[0] && ijk[1] >= lo_[1] && ijk[1] <= hi_[1] &&
                           ijk[2] >= lo_[2] && ijk[2] <= hi_[2];
    if (in_target) {
      if (visit_target_voxel(r.index, mark_of(ijk), stamp, ray, out, sums)) break;
    } else {
      const std::uint8_t s = grid_.state[static_cast<std::size_t>(r.index)];
      if (s == kOccupied) {
        if (ray.previous_unknown_target >= 0) count_rear_side(ray.previous_unknown_target, stamp, out, sums);
        break;
      }
      if (s == kUnknown) ray.visibility *= 0.5;
      ray.previous_unknown_target = -1;
    }
    // Next voxel: cross the nearest boundary.
    const double* t_next = r.t_next;
    const int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2) : (t_next[1] < t_next[2] ? 1 : 2);
    if (t_next[a] > t_exit) break;
    ijk[a] += r.step[a];
    if (ijk[a] < 0 || ijk[a] >= n[a]) break;
    r.index += r.step[a] * stride[a];
    r.t_next[a] += r.t_delta[a];
  }
}

}  // namespace scenewatch::planning
