#include "scenewatch/foreground/handling.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::foreground {

bool exceeds(const DofVector& v, int k, const DofThresholds& th) {
  const double limit = k < 3 ? th.translation_m : th.rotation_deg;
  return std::abs(v[static_cast<std::size_t>(k)]) > limit;
}

HandlingRecorder::HandlingRecorder(const Pose& T_world_support, const Pose& T_world_start, double start_s)
    : T_support_(T_world_support), T_start_(T_world_start), start_s_(start_s) {}

DofFlags HandlingRecorder::add(const Pose& T_world_object, const DofThresholds& thresholds) {
  const DofVector d = dof_delta(T_support_, T_start_, T_world_object);
  DofFlags fresh{};
  DofVector range{};
  for (std::size_t k = 0; k < d.size(); ++k) {
    lo_[k] = std::min(lo_[k], d[k]);
    hi_[k] = std::max(hi_[k], d[k]);
    range[k] = hi_[k] - lo_[k];
  }
  for (int k = 0; k < kDofCount; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (!flagged_[ks] && exceeds(range, k, thresholds)) flagged_[ks] = fresh[ks] = true;
  }
  return fresh;
}

Handling HandlingRecorder::handling(double end_s, const DofThresholds& thresholds) const {
  Handling h;
  h.start_s = start_s_;
  h.end_s = end_s;
  for (int k = 0; k < kDofCount; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    h.range[ks] = hi_[ks] - lo_[ks];
    h.moved[ks] = exceeds(h.range, k, thresholds);
  }
  return h;
}

}  // namespace scenewatch::foreground
