// Regions of a part between closed boundaries in the image: see boundary_cut.h.
#include "boundary_cut.h"

#include <algorithm>
#include <array>
#include <map>

#include "apart_sets.h"
#include "part_shape.h"
#include "union_find.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {

std::vector<std::vector<int>> cut_at_boundaries(const Cloud& cloud, const std::vector<int>& part, const Eigen::Vector3d& sensor_origin,
                                                const BoundaryTest& is_boundary, const EdgePixelTest& is_edge_pixel,
                                                const BoundaryCutParams& params) {
  const int width = static_cast<int>(cloud.width);
  if (cloud.height <= 1 || part.size() < 2 * static_cast<std::size_t>(params.min_points)) return {part};
  // The part's pixels in its bounding box.
  int u0 = width, v0 = static_cast<int>(cloud.height), u1 = -1, v1 = -1;
  for (int i : part) {
    u0 = std::min(u0, i % width), u1 = std::max(u1, i % width);
    v0 = std::min(v0, i / width), v1 = std::max(v1, i / width);
  }
  const int bw = u1 - u0 + 1, bh = v1 - v0 + 1;
  std::vector<int> local(static_cast<std::size_t>(bw) * bh, -1);
  auto at = [&](int u, int v) -> int& { return local[static_cast<std::size_t>(v - v0) * bw + (u - u0)]; };
  for (std::size_t k = 0; k < part.size(); ++k) at(part[k] % width, part[k] / width) = static_cast<int>(k);

  // The angle one pixel spans (1 / focal length): the spacing of two neighbouring points across
  // their ray, over their range; the median of a sample.
  std::vector<double> angles;
  for (std::size_t k = 0; k + 1 < part.size() && angles.size() < 64; k += 16) {
    const int i = part[k];
    if (i % width + 1 > u1 || at(i % width + 1, i / width) < 0) continue;
    const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>(), q = cloud[i + 1].getVector3fMap().cast<double>();
    const Eigen::Vector3d ray = (p - sensor_origin).normalized(), d = q - p;
    angles.push_back((d - ray * ray.dot(d)).norm() / std::max(1e-6, (p - sensor_origin).norm()));
  }
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  const double pixel_angle = angles.empty() ? 1.0 / 525.0 : angles[angles.size() / 2];

  // 1. Regions: neighbouring pixels without a boundary between them.
  const int n = static_cast<int>(part.size());
  UnionFind pixels(n);
  struct Crossing {
    int a, b;         ///< local pixel indices
    double length_m;  ///< the boundary's length between the two pixels: their spacing across the ray
    bool step;        ///< a depth step (else a colour edge)
  };
  std::vector<char> on_outline(n, 0);  ///< a pixel with a 4-neighbour outside the part
  std::vector<Crossing> crossings;
  for (int k = 0; k < n; ++k) {
    const int i = part[k], u = i % width, v = i / width;
    on_outline[k] = u == u0 || u == u1 || v == v0 || v == v1 || at(u - 1, v) < 0 || at(u + 1, v) < 0 ||
                    at(u, v - 1) < 0 || at(u, v + 1) < 0;
    if (is_edge_pixel && is_edge_pixel(i)) continue;
    for (const auto& [du, dv, offset] : {std::array<int, 3>{1, 0, 1}, std::array<int, 3>{0, 1, width}}) {
      if (u + du > u1 || v + dv > v1) continue;
      const int other = at(u + du, v + dv);
      if (other < 0 || (is_edge_pixel && is_edge_pixel(part[other]))) continue;
      const Boundary b = is_boundary(i, offset);
      if (b != Boundary::kNone) {
        const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>(), q = cloud[i + offset].getVector3fMap().cast<double>();
        const Eigen::Vector3d ray = (p - sensor_origin).normalized(), d = q - p;
        crossings.push_back({k, other, (d - ray * ray.dot(d)).norm(), b == Boundary::kDepthStep});
      } else {
        pixels.unite(k, other);
      }
    }
  }
  // Edge pixels (a colour edge's line) belong to no region yet. Each lies between the regions
  // around it (within two pixels: a line may be two pixels wide, and colour may be off depth by
  // as much); the line's length counts as colour boundary between each two of them, and the
  // pixel joins the one most around it.
  std::vector<int> edge_pixels;
  if (is_edge_pixel)
    for (int k = 0; k < n; ++k)
      if (is_edge_pixel(part[k])) edge_pixels.push_back(k);
  if (crossings.empty() && edge_pixels.empty()) return {part};
  std::vector<int> region(n, -1);
  int regions = 0;
  std::vector<char> is_line(n, 0);
  for (int k : edge_pixels) is_line[k] = 1;
  for (int k = 0; k < n; ++k) {
    if (is_line[k]) continue;
    const int root = pixels.find(k);
    if (region[root] < 0) region[root] = regions++;
    region[k] = region[root];
  }
  std::map<std::pair<int, int>, double> colour_m;
  for (int k : edge_pixels) {
    const int i = part[k], u = i % width, v = i / width;
    std::map<int, int> around;
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du) {
        if (u + du < u0 || u + du > u1 || v + dv < v0 || v + dv > v1) continue;
        const int other = at(u + du, v + dv);
        if (other >= 0 && !is_line[other]) ++around[region[other]];
      }
    if (around.empty()) {
      region[k] = regions++;
      continue;
    }
    int best = -1, best_count = 0;
    for (const auto& [r, count] : around) {
      if (count > best_count) best = r, best_count = count;
    }
    region[k] = best;
    // One pixel of line between two regions: its spacing at its range, shared among the pairs.
    const double length = (cloud[i].getVector3fMap().cast<double>() - sensor_origin).norm() * pixel_angle;
    for (auto a = around.begin(); a != around.end(); ++a)
      for (auto b = std::next(a); b != around.end(); ++b) colour_m[{a->first, b->first}] += length;
  }
  if (regions < 2) return {part};

  // 2. Object-sized regions.
  std::vector<PartShape> shapes(regions);
  for (int k = 0; k < n; ++k) shapes[region[k]].add(cloud[part[k]].getVector3fMap().cast<double>());
  std::vector<char> object_sized(regions, 0), reaches_outline(regions, 0);
  for (int k = 0; k < n; ++k) reaches_outline[region[k]] |= on_outline[k];
  int object_sized_count = 0;
  for (int r = 0; r < regions; ++r) {
    object_sized[r] = shapes[r].count >= params.min_points && shapes[r].width() >= params.min_part_size_m;
    object_sized_count += object_sized[r];
  }
  if (object_sized_count < 2) return {part};

  // 3. How regions meet: across a boundary (its length), and in space (neighbouring cells at the
  // clustering tolerance, the way the cluster itself was connected; this bridges holes).
  std::map<std::pair<int, int>, std::pair<double, double>> boundary_m;  // (depth steps, colour edges)
  for (const Crossing& c : crossings) {
    const int ra = region[c.a], rb = region[c.b];
    if (ra == rb) continue;
    auto& length = boundary_m[{std::min(ra, rb), std::max(ra, rb)}];
    (c.step ? length.first : length.second) += c.length_m;
  }
  for (const auto& [pair, length] : colour_m) boundary_m[pair].second += length;
  std::map<std::pair<int, int>, int> touching;
  {
    const VoxelIndex cells(cloud, part, params.cluster_tolerance_m);
    // Local index of each member: members are cloud indices, part is sorted.
    auto local_of = [&](int i) { return static_cast<int>(std::lower_bound(part.begin(), part.end(), i) - part.begin()); };
    std::vector<std::vector<int>> cell_regions(cells.centroids.size());
    for (std::size_t c = 0; c < cells.centroids.size(); ++c) {
      auto& rs = cell_regions[c];
      for (const int* m = cells.members_begin(static_cast<int>(c)); m != cells.members_end(static_cast<int>(c)); ++m)
        rs.push_back(region[local_of(*m)]);
      std::sort(rs.begin(), rs.end());
      rs.erase(std::unique(rs.begin(), rs.end()), rs.end());
    }
    auto meet = [&](const std::vector<int>& x, const std::vector<int>& y) {
      for (int a : x)
        for (int b : y)
          if (a != b) ++touching[{std::min(a, b), std::max(a, b)}];
    };
    for (std::size_t c = 0; c < cells.centroids.size(); ++c) {
      meet(cell_regions[c], cell_regions[c]);
      const auto& xyz = cells.coords[c];
      for (const auto& o : forward_offsets()) {
        const int w = cells.find(xyz[0] + o[0], xyz[1] + o[1], xyz[2] + o[2]);
        if (w >= 0) meet(cell_regions[c], cell_regions[w]);
      }
    }
  }

  // 4. Join regions, most contact first; two object-sized regions with a boundary of object
  // length between them never join, not even through a third region.
  ApartSets apart;
  for (const auto& [pair, length] : boundary_m) {
    if (!object_sized[pair.first] || !object_sized[pair.second]) continue;
    const bool across = reaches_outline[pair.first] && reaches_outline[pair.second];
    if (length.first >= params.min_part_size_m || (across && length.first + length.second >= params.min_part_size_m)) {
      apart[pair.first].insert(pair.second);
      apart[pair.second].insert(pair.first);
    }
  }
  std::vector<std::pair<int, std::pair<int, int>>> ranked;
  for (const auto& [pair, count] : touching) ranked.push_back({count, pair});
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  UnionFind joined(regions);
  for (const auto& [count, pair] : ranked) unite_unless_apart(joined, apart, pair.first, pair.second);
  std::map<int, std::vector<int>> by_root;
  for (int k = 0; k < n; ++k) by_root[joined.find(region[k])].push_back(part[k]);
  if (by_root.size() < 2) return {part};
  // A set that is no object (a fragment touching nothing in space) goes to the largest one.
  std::vector<std::vector<int>> out;
  std::vector<int> leftover;
  for (auto& [root, indices] : by_root) {
    if (static_cast<int>(indices.size()) >= params.min_points) out.push_back(std::move(indices));
    else leftover.insert(leftover.end(), indices.begin(), indices.end());
  }
  if (out.size() < 2) return {part};
  if (!leftover.empty()) {
    auto& largest = *std::max_element(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.size() < b.size(); });
    largest.insert(largest.end(), leftover.begin(), leftover.end());
  }
  for (auto& indices : out) std::sort(indices.begin(), indices.end());
  return out;
}

}  // namespace scenewatch::segmentation
