// Object-level changes: clusters of mismatch evidence, size filter, move pairing, events.
#include "scenewatch/change/objects.h"

#include <tsl/robin_map.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <sstream>

#include "scenewatch/core/hash.h"

namespace scenewatch::change {
namespace {

std::uint64_t cell_key(const Eigen::Vector3d& p, double cell) {
  auto c = [&](double x) { return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(x / cell)) + (1 << 20)) & 0x1fffff; };
  return (c(p.x()) << 42) | (c(p.y()) << 21) | c(p.z());
}

int find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Connected components of points over a grid of `cell` edge, cells 26-connected. Returns a
// component id per point.
std::vector<int> connected_components(const std::vector<Eigen::Vector3d>& points, double cell) {
  tsl::robin_map<std::uint64_t, int, MixHash64> cells;
  std::vector<int> cell_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    auto [it, inserted] = cells.try_emplace(cell_key(points[i], cell), static_cast<int>(cells.size()));
    cell_of[i] = it->second;
  }
  std::vector<int> parent(cells.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [key, id] : cells) {
    const std::int64_t x = static_cast<std::int64_t>(key >> 42), y = static_cast<std::int64_t>((key >> 21) & 0x1fffff),
                       z = static_cast<std::int64_t>(key & 0x1fffff);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const std::uint64_t k = ((static_cast<std::uint64_t>(x + dx) & 0x1fffff) << 42) |
                                  ((static_cast<std::uint64_t>(y + dy) & 0x1fffff) << 21) |
                                  (static_cast<std::uint64_t>(z + dz) & 0x1fffff);
          auto it = cells.find(k);
          if (it == cells.end()) continue;
          const int a = find(parent, id), b = find(parent, it->second);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
  }
  std::vector<int> label(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) label[i] = find(parent, cell_of[i]);
  return label;
}

// Evidence of one side before clustering: world points with colour, pixel and a source index.
struct Evidence {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> rgb;
  std::vector<std::array<int, 2>> pixel;
  std::vector<int> index;  // into the observation, or -1
  std::vector<float> gap;
  std::vector<float> area;  // metric surface each piece of evidence stands for
};

Eigen::Vector3d rgb_of(const PointT& p) { return Eigen::Vector3d(p.r, p.g, p.b); }

std::vector<ChangeCluster> group(const Evidence& ev, ChangeKind kind, double cell, const Config& config) {
  std::vector<ChangeCluster> out;
  if (ev.points.empty()) return out;
  const std::vector<int> label = connected_components(ev.points, cell);
  tsl::robin_map<int, std::vector<int>> members;
  for (std::size_t i = 0; i < label.size(); ++i) members[label[i]].push_back(static_cast<int>(i));
  for (auto& [l, m] : members) {
    if (m.size() < config.min_cluster_points) continue;
    ChangeCluster c;
    c.kind = kind;
    c.box_world.min = c.box_world.max = ev.points[m[0]];
    int u0 = ev.pixel[m[0]][0], u1 = u0, v0 = ev.pixel[m[0]][1], v1 = v0;
    double gap = 0, area = 0;
    for (int i : m) {
      area += ev.area[i];
      c.points_world.push_back(ev.points[i]);
      c.box_world.min = c.box_world.min.cwiseMin(ev.points[i]);
      c.box_world.max = c.box_world.max.cwiseMax(ev.points[i]);
      c.centroid_world += ev.points[i];
      c.mean_rgb += ev.rgb[i];
      gap += ev.gap[i];
      u0 = std::min(u0, ev.pixel[i][0]);
      u1 = std::max(u1, ev.pixel[i][0]);
      v0 = std::min(v0, ev.pixel[i][1]);
      v1 = std::max(v1, ev.pixel[i][1]);
      if (ev.index[i] >= 0) c.indices.push_back(ev.index[i]);
    }
    c.centroid_world /= static_cast<double>(m.size());
    c.mean_rgb /= static_cast<double>(m.size());
    c.mean_gap_m = gap / static_cast<double>(m.size());
    c.evidence_count = m.size();
    c.region = PixelRegion{u0, v0, u1 - u0 + 1, v1 - v0 + 1, static_cast<std::uint32_t>(m.size())};
    if (c.sorted_extent().x() < config.min_object_size_m || area < config.min_object_area_m2) continue;
    std::sort(c.indices.begin(), c.indices.end());
    out.push_back(std::move(c));
  }
  std::sort(out.begin(), out.end(), [](const ChangeCluster& a, const ChangeCluster& b) {
    return a.points_world.size() > b.points_world.size();
  });
  return out;
}

}  // namespace

std::array<int, 2> pixel_of(const Cloud& cloud, int i, const Intrinsics& K) {
  if (cloud.height > 1) return {i % static_cast<int>(cloud.width), i / static_cast<int>(cloud.width)};
  const PointT& p = cloud.points[i];
  return {static_cast<int>(std::lround(K.fx * p.x / p.z + K.cx)), static_cast<int>(std::lround(K.fy * p.y / p.z + K.cy))};
}

Eigen::Vector3d ChangeCluster::sorted_extent() const {
  Eigen::Vector3d e = box_world.max - box_world.min;
  std::sort(e.data(), e.data() + 3, std::greater<double>());
  return e;
}

std::vector<ChangeCluster> cluster_mismatch(const Mismatch& mm, const ClusterInput& in, const Config& config) {
  std::vector<ChangeCluster> out;
  // Added side: points of the observation.
  if (in.after_camera != nullptr) {
    Evidence ev;
    const Cloud& cloud = *in.after_camera;
    for (std::size_t k = 0; k < mm.added.size(); ++k) {
      const int i = mm.added[k];
      const PointT& p = cloud.points[i];
      ev.points.push_back(in.T_world_after * p.getVector3fMap().cast<double>());
      ev.rgb.push_back(rgb_of(p));
      ev.pixel.push_back(pixel_of(cloud, i, in.K_after));
      ev.index.push_back(i);
      ev.gap.push_back(k < mm.added_gap_m.size() ? mm.added_gap_m[k] : 0.f);
      ev.area.push_back(static_cast<float>(p.z * p.z / (in.K_after.fx * in.K_after.fy)));
    }
    auto added = group(ev, ChangeKind::kAdded, config.cluster_voxel_m, config);
    out.insert(out.end(), added.begin(), added.end());
  }
  // Removed side, same-camera pairs: points of BEFORE, in the same pixel grid.
  if (!mm.removed_points.empty() && in.before_camera != nullptr) {
    Evidence ev;
    const Cloud& before = *in.before_camera;
    for (int i : mm.removed_points) {
      const PointT& p = before.points[i];
      ev.points.push_back(in.T_world_before * p.getVector3fMap().cast<double>());
      ev.rgb.push_back(rgb_of(p));
      ev.pixel.push_back(pixel_of(before, i, in.K_after));
      ev.index.push_back(i);
      const PointT& a = in.after_camera->points[i];
      ev.gap.push_back(a.z - p.z);
      ev.area.push_back(static_cast<float>(p.z * p.z / (in.K_after.fx * in.K_after.fy)));
    }
    auto removed = group(ev, ChangeKind::kRemoved, config.cluster_voxel_m, config);
    out.insert(out.end(), removed.begin(), removed.end());
  }
  // Removed side, map path: voxels the rays passed through; BEFORE's points in them, when known.
  // A map voxel holds a surface patch of many points, so a cluster of them needs an eighth of
  // min_cluster_points; dark space (dark_space.h) is volume without a surface, so a cluster of it
  // needs min_cluster_points voxels, as the key says of removed voxels.
  for (const bool dark : {false, true}) {
    Evidence ev;
    for (const auto& m : mm.missing) {
      if (m.dark != dark) continue;
      ev.points.push_back(m.center_world);
      ev.rgb.push_back(Eigen::Vector3d((m.rgb >> 16) & 0xff, (m.rgb >> 8) & 0xff, m.rgb & 0xff));
      ev.pixel.push_back({m.u, m.v});
      ev.index.push_back(-1);
      ev.gap.push_back(m.depth_gap_m);
      ev.area.push_back(static_cast<float>(mm.voxel_m * mm.voxel_m));
    }
    if (ev.points.empty()) continue;
    // Voxel centres one map voxel apart must connect: cluster on the coarser of the two grids.
    const double cell = std::max(config.cluster_voxel_m, mm.voxel_m * 1.01);
    Config voxel_config = config;
    if (!dark) voxel_config.min_cluster_points = std::max<std::size_t>(2, config.min_cluster_points / 8);
    auto removed = group(ev, ChangeKind::kRemoved, cell, voxel_config);
    if (in.before_camera != nullptr && mm.voxel_m > 0) {
      tsl::robin_map<std::uint64_t, int, MixHash64> voxel_cluster;
      for (std::size_t c = 0; c < removed.size(); ++c)
        for (const auto& p : removed[c].points_world) voxel_cluster[cell_key(p, mm.voxel_m)] = static_cast<int>(c);
      const Cloud& before = *in.before_camera;
      for (std::size_t i = 0; i < before.size(); ++i) {
        if (!is_valid(before.points[i])) continue;
        const Eigen::Vector3d w = in.T_world_before * before.points[i].getVector3fMap().cast<double>();
        auto it = voxel_cluster.find(cell_key(w, mm.voxel_m));
        if (it != voxel_cluster.end()) removed[it->second].indices.push_back(static_cast<int>(i));
      }
    }
    out.insert(out.end(), removed.begin(), removed.end());
  }
  return out;
}

double move_similarity(const ChangeCluster& removed, const ChangeCluster& added, const Config& config) {
  // Evidence clusters closer than move_min_distance_m are one object's border residue. Not so
  // whole objects (completed): evidence that left one and entered the other shows the object
  // moved, by however little (2 cm), or turned in place (its centroid may then stay put).
  const bool whole = removed.completed && added.completed;
  if (!whole && (added.centroid_world - removed.centroid_world).norm() < config.move_min_distance_m) return 0.0;
  const Eigen::Vector3d a = removed.sorted_extent(), b = added.sorted_extent();
  double size = 1.0;
  for (int i = 0; i < 2; ++i) {  // the two largest sides; the third is often a partial view
    const double hi = std::max(a(i), b(i)), lo = std::max(1e-3, std::min(a(i), b(i)));
    if (hi / lo > config.move_max_size_ratio) return 0.0;
    size = std::min(size, lo / hi);
  }
  const double colour = (removed.mean_rgb - added.mean_rgb).norm();
  if (colour > config.move_max_color_distance) return 0.0;
  const double c = config.move_max_color_distance > 0 ? 1.0 - colour / config.move_max_color_distance : 1.0;
  return std::max(1e-6, 0.5 * size + 0.5 * c);
}

std::vector<ObjectChange> pair_changes(std::vector<ChangeCluster> clusters, const Config& config) {
  std::vector<int> removed, added;
  for (std::size_t i = 0; i < clusters.size(); ++i) (clusters[i].kind == ChangeKind::kRemoved ? removed : added).push_back(static_cast<int>(i));
  std::vector<std::tuple<double, int, int>> pairs;
  for (int r : removed)
    for (int a : added) {
      const double s = move_similarity(clusters[r], clusters[a], config);
      if (s > 0) pairs.emplace_back(-s, r, a);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> used(clusters.size(), 0);
  std::vector<ObjectChange> out;
  for (const auto& [neg, r, a] : pairs) {
    if (used[r] || used[a]) continue;
    used[r] = used[a] = 1;
    ObjectChange c;
    c.kind = EventKind::kObjectMoved;
    c.before = clusters[r];
    c.after = clusters[a];
    c.similarity = -neg;
    out.push_back(std::move(c));
  }
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    if (used[i]) continue;
    ObjectChange c;
    if (clusters[i].kind == ChangeKind::kAdded) {
      c.kind = EventKind::kObjectAdded;
      c.after = std::move(clusters[i]);
    } else {
      c.kind = EventKind::kObjectRemoved;
      c.before = std::move(clusters[i]);
    }
    out.push_back(std::move(c));
  }
  return out;
}

Event to_event(const ObjectChange& change) {
  Event e;
  e.level = EventLevel::kMismatch;
  e.kind = change.kind;
  // The box and centroid say where the object is now (added, moved) or was (removed).
  const ChangeCluster& where = change.after ? *change.after : *change.before;
  e.box_world = where.box_world;
  e.centroid_world = where.centroid_world;
  e.region = where.region;
  const Eigen::Vector3d ext = where.sorted_extent();
  e.evidence["size_m"] = ext.x();
  e.evidence["mean_gap_m"] = where.mean_gap_m;
  e.evidence["evidence_points"] = static_cast<double>(where.evidence_count);
  if (where.completed) e.evidence["object_points"] = static_cast<double>(where.indices.size());
  std::ostringstream os;
  os.precision(3);
  if (change.before) e.indices_before = change.before->indices;
  if (change.after) e.indices_after = change.after->indices;
  e.pending_ids = change.pending_ids;
  switch (change.kind) {
    case EventKind::kObjectMoved: {
      const Eigen::Vector3d d = change.after->centroid_world - change.before->centroid_world;
      e.displacement_world = d;
      e.score = change.similarity;
      e.evidence["similarity"] = change.similarity;
      e.evidence["distance_m"] = d.norm();
      e.evidence["before_centroid_x"] = change.before->centroid_world.x();
      e.evidence["before_centroid_y"] = change.before->centroid_world.y();
      e.evidence["before_centroid_z"] = change.before->centroid_world.z();
      os << "moved by " << d.norm() << " m (similarity " << change.similarity << "), " << ext.x() << " m object";
      break;
    }
    case EventKind::kObjectAdded:
      e.score = std::min(1.0, where.mean_gap_m / 0.05);
      os << ext.x() << " m object in space seen free, " << where.evidence_count << " points, "
         << where.mean_gap_m << " m in front of the model";
      break;
    default:
      e.score = std::min(1.0, where.mean_gap_m / 0.05);
      os << ext.x() << " m object seen through, " << where.evidence_count << " pieces of evidence, depth "
         << where.mean_gap_m << " m behind it";
      break;
  }
  e.detail = os.str();
  return e;
}

}  // namespace scenewatch::change
