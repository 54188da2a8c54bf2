// Whole-object completion of change clusters from the segmentation of each frame.
#include "scenewatch/change/completion.h"

#include <algorithm>
#include <climits>
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

// One cluster from a group whose members have explaining objects: the objects' points plus the
// members' evidence on no object (the foot of an object below the segmentation's minimum
// height, a part the clustering dropped), which is still this change's.
ChangeCluster completed(const std::vector<ChangeCluster>& clusters, const std::vector<std::vector<int>>& objects,
                        const std::vector<int>& group, const CompletionFrame& frame) {
  const ObjectLabels& labels = *frame.objects;
  ChangeCluster c = clusters[group.front()];
  std::vector<char> taken(labels.members.size(), 0);
  double gap_sum = 0;
  std::size_t evidence = 0;
  c.indices.clear();
  for (int m : group) {
    for (int o : objects[m]) taken[o] = 1;
    for (int i : clusters[m].indices)
      if (labels.object_of[i] < 0) c.indices.push_back(i);
    gap_sum += clusters[m].mean_gap_m * static_cast<double>(clusters[m].evidence_count);
    evidence += clusters[m].evidence_count;
  }
  for (std::size_t o = 0; o < taken.size(); ++o)
    if (taken[o]) c.indices.insert(c.indices.end(), labels.members[o].begin(), labels.members[o].end());
  std::sort(c.indices.begin(), c.indices.end());
  c.indices.erase(std::unique(c.indices.begin(), c.indices.end()), c.indices.end());
  c.evidence_count = evidence;
  c.mean_gap_m = evidence > 0 ? gap_sum / static_cast<double>(evidence) : c.mean_gap_m;
  c.completed = true;
  describe(c, frame);
  return c;
}

}  // namespace

ObjectLabels label_objects(const segmentation::Segmentation& segmentation, std::size_t cloud_size) {
  ObjectLabels labels;
  labels.object_of.assign(cloud_size, -1);
  for (const auto& object : segmentation.objects) {
    const int id = static_cast<int>(labels.members.size());
    for (int i : object.indices) labels.object_of[i] = id;
    labels.members.push_back(object.indices);
  }
  return labels;
}

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
  std::vector<ChangeCluster> out;
  for (const auto& group : merge_groups(clusters, objects)) {
    if (objects[group.front()].empty()) {  // no object explains it (a group of one): keep the evidence
      out.push_back(std::move(clusters[group.front()]));
      continue;
    }
    out.push_back(completed(clusters, objects, group, frame_of(clusters[group.front()].kind, before, after)));
  }
  return out;
}

}  // namespace scenewatch::change
