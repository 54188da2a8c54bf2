// Object-level scoring of change events against true changes.
#include "scenewatch/change/event_scoring.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace scenewatch::change {
namespace {

// |A n B| for two sorted index lists.
std::size_t intersection(std::vector<int> a, std::vector<int> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::size_t n = 0;
  for (std::size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (a[i] < b[j]) {
      ++i;
    } else if (b[j] < a[i]) {
      ++j;
    } else {
      ++n;
      ++i;
      ++j;
    }
  }
  return n;
}

}  // namespace

ChangeScore& ChangeScore::operator+=(const ChangeScore& o) {
  events += o.events;
  true_changes += o.true_changes;
  matched_events += o.matched_events;
  matched_changes += o.matched_changes;
  iou_sum += o.iou_sum;
  return *this;
}

double change_iou(const Event& e, const TrueChange& t) {
  // Only the sides the truth has: a move found where the truth lists a removal (or an addition)
  // is scored on its vanished (or appeared) side.
  const bool use_before = !t.indices_before.empty(), use_after = !t.indices_after.empty();
  const std::size_t inter = (use_before ? intersection(e.indices_before, t.indices_before) : 0) +
                            (use_after ? intersection(e.indices_after, t.indices_after) : 0);
  const std::size_t uni = (use_before ? e.indices_before.size() + t.indices_before.size() : 0) +
                          (use_after ? e.indices_after.size() + t.indices_after.size() : 0) - inter;
  return uni ? static_cast<double>(inter) / uni : 0.0;
}

ChangeScore score_changes(const std::vector<Event>& events, const std::vector<TrueChange>& truth, double iou_threshold) {
  ChangeScore s;
  s.events = events.size();
  s.true_changes = truth.size();
  for (const auto& t : truth) {
    double best = 0;
    for (const auto& e : events) best = std::max(best, change_iou(e, t));
    if (best >= iou_threshold) {
      ++s.matched_changes;
      s.iou_sum += best;
    }
  }
  // An event is right when it matches some true change at the same IoU.
  for (const auto& e : events) {
    double best = 0;
    for (const auto& t : truth) best = std::max(best, change_iou(e, t));
    s.matched_events += best >= iou_threshold ? 1 : 0;
  }
  return s;
}

std::vector<TrueChange> true_changes_from_labels(const std::vector<Eigen::Vector3f>& bx,
                                                 const std::vector<std::uint32_t>& bl,
                                                 const std::vector<Eigen::Vector3f>& ax,
                                                 const std::vector<std::uint32_t>& al, std::uint32_t divisor,
                                                 std::uint32_t min_label, double near_m, std::size_t min_points,
                                                 double kept_fraction) {
  auto objects = [&](const std::vector<Eigen::Vector3f>& xyz, const std::vector<std::uint32_t>& labels) {
    std::map<std::uint32_t, std::vector<int>> out;
    for (std::size_t i = 0; i < xyz.size(); ++i)
      if (labels[i] >= min_label && xyz[i].allFinite()) out[labels[i] / divisor].push_back(static_cast<int>(i));
    return out;
  };
  // One object's pixels read in the other scene: hidden where the other scene has a surface in
  // front (occluded, or hidden before), kept where its depth is the same, changed otherwise.
  const float near = static_cast<float>(near_m);
  auto changed = [&](const std::vector<int>& idx, const std::vector<Eigen::Vector3f>& own,
                     const std::vector<Eigen::Vector3f>& other) {
    std::size_t hidden = 0, seen = 0, kept = 0;
    for (int i : idx) {
      if (static_cast<std::size_t>(i) >= other.size() || !other[i].allFinite()) continue;
      const float dz = other[i].z() - own[i].z();
      if (dz < -near) {
        ++hidden;
        continue;
      }
      ++seen;
      kept += std::abs(dz) <= near ? 1 : 0;
    }
    if (2 * hidden >= idx.size() || seen == 0) return false;  // mostly out of sight: unknown
    return static_cast<double>(kept) < kept_fraction * static_cast<double>(seen);
  };
  std::vector<TrueChange> out;
  for (const auto& [id, idx] : objects(ax, al)) {
    if (idx.size() < min_points || !changed(idx, ax, bx)) continue;
    TrueChange t;
    t.object_id = id;
    t.indices_after = idx;
    out.push_back(std::move(t));
  }
  for (const auto& [id, idx] : objects(bx, bl)) {
    if (idx.size() < min_points || !changed(idx, bx, ax)) continue;
    TrueChange t;
    t.object_id = id;
    t.indices_before = idx;
    out.push_back(std::move(t));
  }
  return out;
}

bool same_camera_by_labels(const std::vector<Eigen::Vector3f>& bx, const std::vector<std::uint32_t>& bl,
                           const std::vector<Eigen::Vector3f>& ax, const std::vector<std::uint32_t>& al,
                           std::uint32_t table_label) {
  std::size_t n = 0, same = 0;
  for (std::size_t i = 0; i < bx.size() && i < ax.size(); ++i) {
    if (bl[i] != table_label || al[i] != table_label || !bx[i].allFinite() || !ax[i].allFinite()) continue;
    ++n;
    same += std::abs(bx[i].z() - ax[i].z()) < 1e-4f ? 1 : 0;
  }
  return n > 1000 && 2 * same > n;
}

}  // namespace scenewatch::change
