// Surface patches of a cluster, cut at depth steps: see surface_patches.h.
#include "surface_patches.h"

#include <tsl/robin_map.h>

#include <algorithm>
#include <array>
#include <cstdint>

#include "scenewatch/core/hash.h"
#include "union_find.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {
namespace {

// The 13 forward offsets of the 26-neighbourhood: each unordered pair of cells once.
const std::vector<std::array<int, 3>>& forward_offsets() {
  static const std::vector<std::array<int, 3>> offsets = [] {
    std::vector<std::array<int, 3>> out;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx > 0 || (dx == 0 && (dy > 0 || (dy == 0 && dz > 0)))) out.push_back({dx, dy, dz});
        }
    return out;
  }();
  return offsets;
}

std::uint64_t pair_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
}

// Two neighbouring pixels of the cluster (positions in it) and whether the surface steps between them.
struct Contact {
  int a, b;
  bool step;
};

}  // namespace

SurfacePatches surface_patches(const Cloud& cloud, const std::vector<int>& cluster, double patch_size_m,
                               const Eigen::Vector3d& sensor_origin, const std::optional<DepthStepParams>& steps) {
  const VoxelIndex grid(cloud, cluster, patch_size_m);
  const int ncells = static_cast<int>(grid.centroids.size());
  SurfacePatches out;
  // Patches: the points of each cell, split into pixel-connected pieces not crossing a step.
  std::vector<int> patch_of_cell;         // plain cells: patch = cell
  std::vector<std::vector<int>> cell_patches(ncells);  // cut cells: the patches of each cell
  std::vector<Contact> contacts;
  std::vector<int> patch_of_pos;          // per cluster position (cut cells only)
  const bool cut = steps && cloud.height > 1;
  if (!cut) {
    out.members.resize(ncells);
    for (int v = 0; v < ncells; ++v) {
      out.members[v].assign(grid.members_begin(v), grid.members_end(v));
      cell_patches[v].push_back(v);
    }
  } else {
    // Position in the cluster and cell of each pixel of the cluster, over its bounding box.
    const std::size_t n = cluster.size();
    const int w = static_cast<int>(cloud.width);
    int u0 = w, v0 = static_cast<int>(cloud.height), u1 = -1, v1 = -1;
    for (int i : cluster) {
      u0 = std::min(u0, i % w), u1 = std::max(u1, i % w);
      v0 = std::min(v0, i / w), v1 = std::max(v1, i / w);
    }
    const int box_w = u1 - u0 + 1;
    std::vector<int> pos_in_box(static_cast<std::size_t>(box_w) * (v1 - v0 + 1), -1);
    auto pos_of = [&](int i) {
      const int u = i % w - u0, v = i / w - v0;
      return u < 0 || u >= box_w || v < 0 || v > v1 - v0 ? -1 : pos_in_box[static_cast<std::size_t>(v) * box_w + u];
    };
    for (std::size_t k = 0; k < n; ++k)
      pos_in_box[static_cast<std::size_t>(cluster[k] / w - v0) * box_w + cluster[k] % w - u0] = static_cast<int>(k);
    std::vector<int> cell_of_pos(n, -1);
    for (int v = 0; v < ncells; ++v)
      for (const int* i = grid.members_begin(v); i != grid.members_end(v); ++i) cell_of_pos[pos_of(*i)] = v;
    const DepthSteps step_test(cloud, sensor_origin, *steps, u0, v0, u1, v1);
    UnionFind uf(n);
    for (std::size_t k = 0; k < n; ++k) {
      const int i = cluster[k];
      if (cell_of_pos[k] < 0) continue;  // invalid point
      for (const int offset : {1, w}) {
        const int j = i + offset;
        if (offset == 1 && j % w == 0) continue;
        const int pj = pos_of(j);
        if (pj < 0 || cell_of_pos[pj] < 0) continue;
        const bool step = step_test.is_step(i, offset);
        if (!step && cell_of_pos[pj] == cell_of_pos[k]) uf.unite(static_cast<int>(k), pj);
        else contacts.push_back({static_cast<int>(k), pj, step});
      }
    }
    patch_of_pos.assign(n, -1);
    std::vector<int> patch_of_root(n, -1);
    for (std::size_t k = 0; k < n; ++k) {
      if (cell_of_pos[k] < 0) continue;
      const int root = uf.find(static_cast<int>(k));
      if (patch_of_root[root] < 0) {
        patch_of_root[root] = static_cast<int>(out.members.size());
        out.members.emplace_back();
        cell_patches[cell_of_pos[k]].push_back(patch_of_root[root]);
      }
      patch_of_pos[k] = patch_of_root[root];
      out.members[patch_of_root[root]].push_back(cluster[k]);
    }
  }
  // Neighbouring patches: all pairs of patches of neighbouring cells, and of one cell.
  for (int v = 0; v < ncells; ++v) {
    const auto& c = grid.coords[v];
    const auto& pv = cell_patches[v];
    for (std::size_t x = 0; x < pv.size(); ++x)
      for (std::size_t y = x + 1; y < pv.size(); ++y) out.adjacent.emplace_back(pv[x], pv[y]);
    for (const auto& o : forward_offsets()) {
      const int u = grid.find(c[0] + o[0], c[1] + o[1], c[2] + o[2]);
      if (u < 0) continue;
      for (int a : pv)
        for (int b : cell_patches[u]) out.adjacent.emplace_back(a, b);
    }
  }
  out.stepped.assign(out.adjacent.size(), 0);
  out.touching.assign(out.adjacent.size(), 1);
  if (!cut) return out;
  // Pixel contacts of each pair: a pair is a step when most of them are, and touching when
  // there is any.
  tsl::robin_map<std::uint64_t, int, MixHash64> pair_index;
  pair_index.reserve(out.adjacent.size());
  for (std::size_t e = 0; e < out.adjacent.size(); ++e) pair_index[pair_key(out.adjacent[e].first, out.adjacent[e].second)] = static_cast<int>(e);
  std::vector<std::array<int, 2>> votes(out.adjacent.size(), {0, 0});  // (continuous, step)
  for (const Contact& t : contacts) {
    const int a = patch_of_pos[t.a], b = patch_of_pos[t.b];
    if (a == b) continue;
    auto it = pair_index.find(pair_key(a, b));
    if (it != pair_index.end()) ++votes[it->second][t.step ? 1 : 0];
  }
  for (std::size_t e = 0; e < out.adjacent.size(); ++e) {
    out.touching[e] = votes[e][0] + votes[e][1] > 0;
    out.stepped[e] = votes[e][1] > votes[e][0];
  }
  return out;
}

}  // namespace scenewatch::segmentation
