#include "scenewatch/io/bag/tf_tree.h"

#include <algorithm>
#include <cstdio>

namespace scenewatch::io::bag {
namespace {

std::string seconds(double t) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6f s", t);
  return b;
}

}  // namespace

void TfTree::add(const StampedTransform& t, bool is_static) {
  auto it = edge_of_child_.find(t.child);
  if (it == edge_of_child_.end()) {
    it = edge_of_child_.emplace(t.child, edges_.size()).first;
    edges_.push_back({t.parent, t.child, is_static, {}, true});
  }
  Edge& e = edges_[it->second];
  if (e.parent != t.parent) return;  // a second parent breaks TF's tree: the first one stays (as tf2 warns and keeps)
  if (is_static) {
    e.is_static = true;
    e.samples.assign(1, {t.stamp_s, t.T_parent_child});  // the latest static transform wins
    return;
  }
  if (!e.samples.empty() && t.stamp_s < e.samples.back().first) e.sorted = false;
  e.samples.emplace_back(t.stamp_s, t.T_parent_child);
  if (!e.sorted) {
    std::stable_sort(e.samples.begin(), e.samples.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    e.sorted = true;
  }
}

void TfTree::forget_before(double stamp_s) {
  for (Edge& e : edges_) {
    if (e.is_static || e.samples.size() < 2) continue;
    auto first_kept = std::lower_bound(e.samples.begin(), e.samples.end(), stamp_s, [](const auto& a, double v) { return a.first < v; });
    if (first_kept != e.samples.begin()) --first_kept;  // the one before the time, for interpolation
    e.samples.erase(e.samples.begin(), first_kept);
  }
}

bool TfTree::has_frame(const std::string& frame) const {
  if (edge_of_child_.count(frame)) return true;
  return std::any_of(edges_.begin(), edges_.end(), [&](const Edge& e) { return e.parent == frame; });
}

std::string TfTree::root_of(const std::string& frame) const {
  std::string f = frame;
  for (std::size_t guard = 0; guard <= edges_.size(); ++guard) {
    auto it = edge_of_child_.find(f);
    if (it == edge_of_child_.end()) return f;
    f = edges_[it->second].parent;
  }
  return f;  // a cycle: no root
}

Result<Pose> TfTree::at(const Edge& e, double t, double tolerance_s) const {
  const auto& s = e.samples;
  if (e.is_static || s.size() == 1) {
    if (e.is_static || std::abs(s[0].first - t) <= tolerance_s) return s[0].second;
  }
  if (t <= s.front().first) {
    if (s.front().first - t <= tolerance_s) return s.front().second;
  } else if (t >= s.back().first) {
    if (t - s.back().first <= tolerance_s) return s.back().second;
  } else {
    const auto hi = std::lower_bound(s.begin(), s.end(), t, [](const auto& a, double v) { return a.first < v; });
    const auto lo = hi - 1;
    const double span = hi->first - lo->first;
    const double a = span > 0 ? (t - lo->first) / span : 0.0;
    Pose T = Pose::Identity();
    const Eigen::Quaterniond q0(lo->second.linear()), q1(hi->second.linear());
    T.linear() = q0.slerp(a, q1).toRotationMatrix();
    T.translation() = (1 - a) * lo->second.translation() + a * hi->second.translation();
    return T;
  }
  return not_found("no transform '" + e.parent + "' -> '" + e.child + "' at " + seconds(t) + " on /tf: it has " +
                   std::to_string(s.size()) + " samples from " + seconds(s.front().first) + " to " + seconds(s.back().first) +
                   " (tolerance " + seconds(tolerance_s) + ")");
}

Result<Pose> TfTree::lookup(const std::string& target, const std::string& source, double stamp_s, double tolerance_s) const {
  // The chains from each frame up to its root; they meet at the nearest common ancestor.
  auto chain = [&](const std::string& from) {
    std::vector<std::string> frames{from};
    while (frames.size() <= edges_.size() + 1) {
      auto it = edge_of_child_.find(frames.back());
      if (it == edge_of_child_.end()) break;
      frames.push_back(edges_[it->second].parent);
    }
    return frames;
  };
  for (const auto* f : {&target, &source}) {
    if (!has_frame(*f)) return not_found("no frame '" + *f + "' on /tf or /tf_static");
  }
  const auto up_target = chain(target), up_source = chain(source);
  std::size_t i_common = up_target.size();
  std::size_t j_common = 0;
  for (std::size_t i = 0; i < up_target.size() && i_common == up_target.size(); ++i) {
    for (std::size_t j = 0; j < up_source.size(); ++j) {
      if (up_target[i] == up_source[j]) {
        i_common = i;
        j_common = j;
        break;
      }
    }
  }
  if (i_common == up_target.size()) {
    return not_found("frames '" + target + "' (under '" + up_target.back() + "') and '" + source + "' (under '" + up_source.back() +
                     "') are not connected on /tf and /tf_static");
  }
  // T_common_source = T_common_.. * ... * T_parent(source)_source, and the same for the target.
  auto to_common = [&](const std::vector<std::string>& up, std::size_t n) -> Result<Pose> {
    Pose T = Pose::Identity();
    for (std::size_t k = 0; k < n; ++k) {
      const Edge& e = edges_[edge_of_child_.at(up[k])];
      auto Tk = at(e, stamp_s, tolerance_s);
      if (!Tk) return Tk.error();
      T = *Tk * T;
    }
    return T;
  };
  auto T_common_source = to_common(up_source, j_common);
  if (!T_common_source) return T_common_source.error();
  auto T_common_target = to_common(up_target, i_common);
  if (!T_common_target) return T_common_target.error();
  return Pose(T_common_target->inverse() * *T_common_source);
}

}  // namespace scenewatch::io::bag
