// Whole-object completion of change clusters from the segmentation of each frame.
#include "scenewatch/change/whole_objects.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numeric>

namespace scenewatch::change {
namespace {

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

const CompletionFrame& frame_of(ChangeKind kind, const CompletionFrame& before, const CompletionFrame& after) {
  return kind == ChangeKind::kAdded ? after : before;
}

bool usable(const CompletionFrame& f) { return f.cloud_camera != nullptr && f.objects != nullptr; }

// The other frame of the pair, asked about a point of a completion: does it see that surface
// where it is, on an object of its own that no change claims? Then the surface stayed, on
// something that did not change (a box under a new one, an object partly hidden behind a new
// one), and is not part of the change. Needs the other frame's pixel grid (organized cloud).
class Witness {
 public:
  Witness(const CompletionFrame& frame, const std::vector<char>& claimed, const Config& config)
      : frame_(frame), claimed_(claimed), config_(config), T_camera_world_(frame.T_world_camera.inverse()) {}

  bool sees_unchanged(const Eigen::Vector3d& p_world) const {
    if (!usable(frame_) || frame_.cloud_camera->height <= 1 || !frame_.K.valid()) return false;
    const Cloud& cloud = *frame_.cloud_camera;
    const Eigen::Vector3d q = T_camera_world_ * p_world;
    if (q.z() <= 0) return false;
    const long u = std::lround(frame_.K.fx * q.x() / q.z() + frame_.K.cx);
    const long v = std::lround(frame_.K.fy * q.y() / q.z() + frame_.K.cy);
    if (u < 0 || v < 0 || u >= static_cast<long>(cloud.width) || v >= static_cast<long>(cloud.height)) return false;
    const std::size_t j = static_cast<std::size_t>(v) * cloud.width + static_cast<std::size_t>(u);
    const PointT& seen = cloud.points[j];
    if (!is_valid(seen) || std::abs(seen.z - q.z()) > tolerance_m(config_, q.z())) return false;
    const int o = frame_.objects->object_of[j];
    return o >= 0 && !claimed_[o];
  }

 private:
  const CompletionFrame& frame_;
  const std::vector<char>& claimed_;
  const Config& config_;
  Pose T_camera_world_;
};

// Per object of `frame`: whether it explains some cluster of that frame's kind.
std::vector<char> claimed_objects(const std::vector<ChangeCluster>& clusters, const std::vector<std::vector<int>>& objects,
                                  ChangeKind kind, const CompletionFrame& frame) {
  std::vector<char> claimed(usable(frame) ? frame.objects->members.size() : 0, 0);
  for (std::size_t i = 0; i < clusters.size(); ++i)
    if (clusters[i].kind == kind)
      for (int o : objects[i]) claimed[o] = 1;
  return claimed;
}

// Groups of clusters to become one: clusters of one kind that share an explaining object.
// Groups come in the order of their first member.
std::vector<std::vector<int>> merge_groups(const std::vector<ChangeCluster>& clusters,
                                           const std::vector<std::vector<int>>& objects) {
  std::vector<int> parent(clusters.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (ChangeKind kind : {ChangeKind::kAdded, ChangeKind::kRemoved}) {
    std::vector<std::pair<int, int>> claims;  // (object, cluster)
    for (std::size_t i = 0; i < clusters.size(); ++i)
      if (clusters[i].kind == kind)
        for (int o : objects[i]) claims.emplace_back(o, static_cast<int>(i));
    std::sort(claims.begin(), claims.end());
    for (std::size_t k = 1; k < claims.size(); ++k) {
      if (claims[k].first != claims[k - 1].first) continue;
      const int a = find_root(parent, claims[k].second), b = find_root(parent, claims[k - 1].second);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of(clusters.size(), -1);
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    const int r = find_root(parent, static_cast<int>(i));
    if (group_of[r] < 0) {
      group_of[r] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of[r]].push_back(static_cast<int>(i));
  }
  return groups;
}

// Appends an ascending run to an ascending list, keeping it ascending.
void merge_run(std::vector<int>& sorted, const std::vector<int>& run) {
  const auto mid = static_cast<std::ptrdiff_t>(sorted.size());
  sorted.insert(sorted.end(), run.begin(), run.end());
  std::inplace_merge(sorted.begin(), sorted.begin() + mid, sorted.end());
}

// Points, box, centroid, colour and pixel region of a cluster from its indices in `frame`.
void describe(ChangeCluster& c, const CompletionFrame& frame) {
  const Cloud& cloud = *frame.cloud_camera;
  c.points_world.clear();
  c.points_world.reserve(c.indices.size());
  c.centroid_world.setZero();
  c.mean_rgb.setZero();
  int u0 = INT_MAX, v0 = INT_MAX, u1 = INT_MIN, v1 = INT_MIN;
  for (int i : c.indices) {
    const PointT& p = cloud.points[i];
    const Eigen::Vector3d w = frame.T_world_camera * p.getVector3fMap().cast<double>();
    c.points_world.push_back(w);
    c.centroid_world += w;
    c.mean_rgb += Eigen::Vector3d(p.r, p.g, p.b);
    const auto px = pixel_of(cloud, i, frame.K);
    u0 = std::min(u0, px[0]);
    u1 = std::max(u1, px[0]);
    v0 = std::min(v0, px[1]);
    v1 = std::max(v1, px[1]);
  }
  const auto n = static_cast<double>(c.indices.size());
  c.centroid_world /= n;
  c.mean_rgb /= n;
  c.box_world = {c.points_world.front(), c.points_world.front()};
  for (const auto& w : c.points_world) c.box_world = c.box_world.united({w, w});
  c.region = PixelRegion{u0, v0, u1 - u0 + 1, v1 - v0 + 1, static_cast<std::uint32_t>(c.indices.size())};
}

// One cluster from a group whose members have explaining objects: the objects' points that the
// other frame does not see unchanged, plus the members' evidence on no object (the foot of an
// object below the segmentation's minimum height, a part the clustering dropped), which is still
// this change's.
ChangeCluster completed(const std::vector<ChangeCluster>& clusters, const std::vector<std::vector<int>>& objects,
                        const std::vector<int>& group, const CompletionFrame& frame, const Witness& other) {
  const ObjectLabels& labels = *frame.objects;
  ChangeCluster c;
  c.kind = clusters[group.front()].kind;
  c.completed = true;
  std::vector<char> taken(labels.members.size(), 0);
  double gap_sum = 0;
  std::vector<int> run;
  // Every run below is ascending and disjoint from the others (clusters share no evidence,
  // objects no points, and this evidence lies on no object): merging keeps the indices sorted.
  for (int m : group) {
    for (int o : objects[m]) taken[o] = 1;
    run.clear();
    for (int i : clusters[m].indices)
      if (labels.object_of[i] < 0) run.push_back(i);
    merge_run(c.indices, run);
    gap_sum += clusters[m].mean_gap_m * static_cast<double>(clusters[m].evidence_count);
    c.evidence_count += clusters[m].evidence_count;
  }
  const Cloud& cloud = *frame.cloud_camera;
  for (std::size_t o = 0; o < taken.size(); ++o) {
    if (!taken[o]) continue;
    run.clear();
    for (int i : labels.members[o])
      if (!other.sees_unchanged(frame.T_world_camera * cloud.points[i].getVector3fMap().cast<double>())) run.push_back(i);
    merge_run(c.indices, run);
  }
  c.mean_gap_m = c.evidence_count > 0 ? gap_sum / static_cast<double>(c.evidence_count) : 0.0;
  describe(c, frame);
  return c;
}

// A cluster of evidence over several explaining objects (evidence is grouped on a grid, so two
// new objects side by side make one cluster) becomes one cluster per object: the evidence on each
// object goes with it, the rest with the object carrying most of the evidence. The segmentation
// says what an object is; the grid does not.
void split_by_object(std::vector<ChangeCluster>& clusters, std::vector<std::vector<int>>& objects,
                     const CompletionFrame& before, const CompletionFrame& after) {
  std::vector<ChangeCluster> out_clusters;
  std::vector<std::vector<int>> out_objects;
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    if (objects[i].size() <= 1) {
      out_clusters.push_back(std::move(clusters[i]));
      out_objects.push_back(std::move(objects[i]));
      continue;
    }
    const ObjectLabels& labels = *frame_of(clusters[i].kind, before, after).objects;
    const std::vector<int>& explaining = objects[i];
    std::vector<std::size_t> on(explaining.size(), 0);
    auto part_of = [&](int index) {
      const auto it = std::find(explaining.begin(), explaining.end(), labels.object_of[index]);
      return it == explaining.end() ? -1 : static_cast<int>(it - explaining.begin());
    };
    for (int index : clusters[i].indices)
      if (const int k = part_of(index); k >= 0) ++on[k];
    const auto main = static_cast<int>(std::max_element(on.begin(), on.end()) - on.begin());
    std::vector<ChangeCluster> parts(explaining.size());
    for (int index : clusters[i].indices) {
      const int k = part_of(index);
      parts[k >= 0 ? k : main].indices.push_back(index);
    }
    const auto total = static_cast<double>(clusters[i].indices.size());
    for (std::size_t k = 0; k < parts.size(); ++k) {
      parts[k].kind = clusters[i].kind;
      parts[k].mean_gap_m = clusters[i].mean_gap_m;
      parts[k].evidence_count = static_cast<std::size_t>(
          std::lround(static_cast<double>(clusters[i].evidence_count) * static_cast<double>(parts[k].indices.size()) / total));
      out_clusters.push_back(std::move(parts[k]));
      out_objects.push_back({explaining[k]});
    }
  }
  clusters = std::move(out_clusters);
  objects = std::move(out_objects);
}

}  // namespace

std::vector<int> explaining_objects(const std::vector<int>& evidence, const ObjectLabels& labels, const Config& config) {
  std::vector<std::size_t> on(labels.members.size(), 0);
  for (int i : evidence) {
    const int o = labels.object_of[i];
    if (o >= 0) ++on[o];
  }
  std::vector<int> out;
  const auto total = static_cast<double>(evidence.size());
  for (std::size_t o = 0; o < on.size(); ++o) {
    if (on[o] == 0) continue;
    const auto n = static_cast<double>(on[o]);
    if (n >= config.completion_evidence_share * total ||
        n >= config.completion_object_share * static_cast<double>(labels.members[o].size())) {
      out.push_back(static_cast<int>(o));
    }
  }
  return out;
}

std::vector<ChangeCluster> complete_clusters(std::vector<ChangeCluster> clusters, const CompletionFrame& before,
                                             const CompletionFrame& after, const Config& config) {
  std::vector<std::vector<int>> objects(clusters.size());
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    const CompletionFrame& f = frame_of(clusters[i].kind, before, after);
    if (usable(f)) objects[i] = explaining_objects(clusters[i].indices, *f.objects, config);
  }
  split_by_object(clusters, objects, before, after);
  const std::vector<char> claimed_before = claimed_objects(clusters, objects, ChangeKind::kRemoved, before);
  const std::vector<char> claimed_after = claimed_objects(clusters, objects, ChangeKind::kAdded, after);
  const Witness witness_before(before, claimed_before, config), witness_after(after, claimed_after, config);
  std::vector<ChangeCluster> out;
  for (const auto& group : merge_groups(clusters, objects)) {
    if (objects[group.front()].empty()) {  // no object explains it (a group of one): keep the evidence
      out.push_back(std::move(clusters[group.front()]));
      continue;
    }
    const bool added = clusters[group.front()].kind == ChangeKind::kAdded;
    out.push_back(completed(clusters, objects, group, added ? after : before, added ? witness_before : witness_after));
  }
  return out;
}

}  // namespace scenewatch::change
