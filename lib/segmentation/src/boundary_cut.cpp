// Regions of a part between closed boundaries in the image: see boundary_cut.h.
#include "boundary_cut.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>

#include "apart_sets.h"
#include "part_image.h"
#include "part_shape.h"
#include "union_find.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {
namespace {

/// The spacing of the points at cloud indices i and j across the ray from `sensor_origin` to i.
double spacing_across_ray(const Cloud& cloud, int i, int j, const Eigen::Vector3d& sensor_origin) {
  const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>(), q = cloud[j].getVector3fMap().cast<double>();
  const Eigen::Vector3d ray = (p - sensor_origin).normalized(), d = q - p;
  return (d - ray * ray.dot(d)).norm();
}

/// The angle one pixel spans (1 / focal length): the spacing of two neighbouring points across
/// their ray, over their range; the median of a sample.
double pixel_angle(const Cloud& cloud, const std::vector<int>& part, PartImage& image, const Eigen::Vector3d& sensor_origin) {
  const int width = image.width;
  std::vector<double> angles;
  for (std::size_t k = 0; k + 1 < part.size() && angles.size() < 64; k += 16) {
    const int i = part[k];
    if (i % width + 1 > image.u1 || image.at(i % width + 1, i / width) < 0) continue;
    const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>();
    angles.push_back(spacing_across_ray(cloud, i, i + 1, sensor_origin) / std::max(1e-6, (p - sensor_origin).norm()));
  }
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  return angles.empty() ? 1.0 / 525.0 : angles[angles.size() / 2];
}

struct Crossing {
  int a, b;         ///< local pixel indices
  double length_m;  ///< the boundary's length between the two pixels: their spacing across the ray
  bool step;        ///< a depth step (else a colour edge)
};

/// Step 1a: neighbouring pixels without a boundary between them joined; the boundaries crossed.
struct PixelLinks {
  UnionFind pixels;
  std::vector<char> on_outline;  ///< a pixel with a 4-neighbour outside the part
  std::vector<Crossing> crossings;
};

// The four neighbours of a pixel, in the order of PixelLinks' open bits: right, below, left, above.
constexpr std::array<std::array<int, 2>, 4> kSides{{{1, 0}, {0, 1}, {-1, 0}, {0, -1}}};

/// The part's local index of pixel k's neighbour on `side` (kSides), -1 outside the part.
int neighbour(const std::vector<int>& part, const PartImage& image, int k, int side) {
  const int i = part[k];
  return image.find(i % image.width + kSides[side][0], i / image.width + kSides[side][1]);
}

// Step 1a': the pixels at a step join, round by round, the region most of their placed
// neighbours (those `open` reaches, with no boundary between) belong to; one with none keeps a
// region of its own.
void place_step_pixels(const std::vector<int>& part, const PartImage& image, const std::vector<std::uint8_t>& open,
                       const std::vector<char>& at_step, UnionFind& pixels) {
  const int n = static_cast<int>(part.size());
  std::vector<char> placed(n, 1);
  std::vector<int> pending;
  for (int k = 0; k < n; ++k)
    if (at_step[k]) placed[k] = 0, pending.push_back(k);
  while (!pending.empty()) {
    std::vector<std::pair<int, int>> joins;  // (pixel, region root)
    std::vector<int> still;
    for (int k : pending) {
      std::array<int, 4> roots{};
      std::array<int, 4> votes{};
      int distinct = 0;
      for (int side = 0; side < 4; ++side) {
        if (!(open[k] & (1u << side))) continue;
        const int other = neighbour(part, image, k, side);
        if (!placed[other]) continue;
        const int root = pixels.find(other);
        int r = 0;
        while (r < distinct && roots[r] != root) ++r;
        if (r == distinct) roots[distinct++] = root;
        ++votes[r];
      }
      int best = -1, best_votes = 0;
      for (int r = 0; r < distinct; ++r)
        if (votes[r] > best_votes || (votes[r] == best_votes && roots[r] < best)) best = roots[r], best_votes = votes[r];
      if (best >= 0) joins.emplace_back(k, best);
      else still.push_back(k);
    }
    if (joins.empty()) break;
    for (const auto& [k, root] : joins) {
      pixels.unite(k, root);
      placed[k] = 1;
    }
    pending.swap(still);
  }
}

// A line of depth steps is decided pair by pair, and one pair along it that misses the test (a
// pixel at a projector shadow's rim, a corner of a staircase boundary) would join the regions on
// its two sides. So the pixels at a step (either end of a crossing) take no part in forming the
// regions and are placed afterwards (place_step_pixels). A gap of one pair between crossings of
// one line, whose two pixels are both at a step, no longer joins the regions.
PixelLinks link_pixels(const Cloud& cloud, const std::vector<int>& part, PartImage& image,
                       const Eigen::Vector3d& sensor_origin, const BoundaryTest& is_boundary,
                       const EdgePixelTest& is_edge_pixel) {
  const int n = static_cast<int>(part.size()), width = image.width;
  const int u0 = image.u0, v0 = image.v0, u1 = image.u1, v1 = image.v1;
  PixelLinks links{UnionFind(n), std::vector<char>(n, 0), {}};
  std::vector<std::uint8_t> open(n, 0);  // per pixel, a bit per side (kSides) with no boundary
  std::vector<char> at_step(n, 0);
  for (int k = 0; k < n; ++k) {
    const int i = part[k], u = i % width, v = i / width;
    links.on_outline[k] = u == u0 || u == u1 || v == v0 || v == v1 || image.at(u - 1, v) < 0 ||
                          image.at(u + 1, v) < 0 || image.at(u, v - 1) < 0 || image.at(u, v + 1) < 0;
    if (is_edge_pixel && is_edge_pixel(i)) continue;
    for (int side = 0; side < 2; ++side) {  // right and below: each pair once
      const int du = kSides[side][0], dv = kSides[side][1];
      if (u + du > u1 || v + dv > v1) continue;
      const int other = image.at(u + du, v + dv);
      if (other < 0 || (is_edge_pixel && is_edge_pixel(part[other]))) continue;
      const int offset = du + dv * width;
      const Boundary b = is_boundary(i, offset);
      if (b != Boundary::kNone) {
        links.crossings.push_back({k, other, spacing_across_ray(cloud, i, i + offset, sensor_origin), b == Boundary::kDepthStep});
        if (b == Boundary::kDepthStep) at_step[k] = at_step[other] = 1;
      } else {
        open[k] |= static_cast<std::uint8_t>(1u << side);
        open[other] |= static_cast<std::uint8_t>(1u << (side + 2));
      }
    }
  }
  for (int k = 0; k < n; ++k) {
    if (at_step[k]) continue;
    for (int side = 0; side < 2; ++side) {
      if (!(open[k] & (1u << side))) continue;
      const int other = neighbour(part, image, k, side);
      if (!at_step[other]) links.pixels.unite(k, other);
    }
  }
  place_step_pixels(part, image, open, at_step, links.pixels);
  return links;
}

/// Step 1b: each pixel's region, and the length of colour-edge line between each two regions.
struct Regions {
  std::vector<int> region;  ///< per local pixel
  int count = 0;
  std::map<std::pair<int, int>, double> colour_m;
};

// Edge pixels (a colour edge's line) belong to no region yet. Each lies between the regions
// around it (within two pixels: a line may be two pixels wide, and colour may be off depth by
// as much); the line's length counts as colour boundary between each two of them, and the
// pixel joins the one most around it.
Regions label_regions(const Cloud& cloud, const std::vector<int>& part, PartImage& image, UnionFind& pixels,
                      const std::vector<int>& edge_pixels, double pixel_angle, const Eigen::Vector3d& sensor_origin) {
  const int n = static_cast<int>(part.size()), width = image.width;
  Regions out;
  std::vector<int>& region = out.region;
  int& regions = out.count;
  region.assign(n, -1);
  std::vector<char> is_line(n, 0);
  for (int k : edge_pixels) is_line[k] = 1;
  for (int k = 0; k < n; ++k) {
    if (is_line[k]) continue;
    const int root = pixels.find(k);
    if (region[root] < 0) region[root] = regions++;
    region[k] = region[root];
  }
  for (int k : edge_pixels) {
    const int i = part[k], u = i % width, v = i / width;
    std::map<int, int> around;
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du) {
        if (u + du < image.u0 || u + du > image.u1 || v + dv < image.v0 || v + dv > image.v1) continue;
        const int other = image.at(u + du, v + dv);
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
      for (auto b = std::next(a); b != around.end(); ++b) out.colour_m[{a->first, b->first}] += length;
  }
  return out;
}

/// Step 3a: the boundary between each two regions: (depth steps, colour edges), metres.
std::map<std::pair<int, int>, std::pair<double, double>> boundary_lengths(const std::vector<Crossing>& crossings,
                                                                          const Regions& regions) {
  std::map<std::pair<int, int>, std::pair<double, double>> boundary_m;
  for (const Crossing& c : crossings) {
    const int ra = regions.region[c.a], rb = regions.region[c.b];
    if (ra == rb) continue;
    auto& length = boundary_m[{std::min(ra, rb), std::max(ra, rb)}];
    (c.step ? length.first : length.second) += c.length_m;
  }
  for (const auto& [pair, length] : regions.colour_m) boundary_m[pair].second += length;
  return boundary_m;
}

/// Step 3b: how often two regions meet in space: neighbouring cells at the clustering tolerance,
/// the way the cluster itself was connected (this bridges holes).
std::map<std::pair<int, int>, int> touching_regions(const Cloud& cloud, const std::vector<int>& part,
                                                    const std::vector<int>& region, double cluster_tolerance_m) {
  std::map<std::pair<int, int>, int> touching;
  const VoxelIndex cells(cloud, part, cluster_tolerance_m);
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
  return touching;
}

/// Step 4: the regions joined, most contact first; two object-sized regions with a boundary of
/// object length between them never join, not even through a third region. Part indices by root.
std::map<int, std::vector<int>> join_regions(const std::vector<int>& part, const std::vector<int>& region, int regions,
                                             const std::vector<char>& object_sized,
                                             const std::vector<char>& reaches_outline,
                                             const std::map<std::pair<int, int>, std::pair<double, double>>& boundary_m,
                                             const std::map<std::pair<int, int>, int>& touching,
                                             const BoundaryCutParams& params) {
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
  for (std::size_t k = 0; k < part.size(); ++k) by_root[joined.find(region[k])].push_back(part[k]);
  return by_root;
}

/// The joined sets with at least min_points points, each sorted; a set that is no object (a
/// fragment touching nothing in space) goes to the largest one. Fewer than two: `{part}`.
std::vector<std::vector<int>> pieces(std::map<int, std::vector<int>>& by_root, const std::vector<int>& part, int min_points) {
  std::vector<std::vector<int>> out;
  std::vector<int> leftover;
  for (auto& [root, indices] : by_root) {
    if (static_cast<int>(indices.size()) >= min_points) out.push_back(std::move(indices));
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

}  // namespace

std::vector<std::vector<int>> cut_at_boundaries(const Cloud& cloud, const std::vector<int>& part, const Eigen::Vector3d& sensor_origin,
                                                const BoundaryTest& is_boundary, const EdgePixelTest& is_edge_pixel,
                                                const BoundaryCutParams& params) {
  if (cloud.height <= 1 || part.size() < 2 * static_cast<std::size_t>(params.min_points)) return {part};
  PartImage image(cloud, part);
  const double angle = pixel_angle(cloud, part, image, sensor_origin);

  // 1. Regions: neighbouring pixels without a boundary between them.
  const int n = static_cast<int>(part.size());
  PixelLinks links = link_pixels(cloud, part, image, sensor_origin, is_boundary, is_edge_pixel);
  std::vector<int> edge_pixels;
  if (is_edge_pixel)
    for (int k = 0; k < n; ++k)
      if (is_edge_pixel(part[k])) edge_pixels.push_back(k);
  if (links.crossings.empty() && edge_pixels.empty()) return {part};
  const Regions regions = label_regions(cloud, part, image, links.pixels, edge_pixels, angle, sensor_origin);
  if (regions.count < 2) return {part};

  // 2. Object-sized regions.
  std::vector<PartShape> shapes(regions.count);
  for (int k = 0; k < n; ++k) shapes[regions.region[k]].add(cloud[part[k]].getVector3fMap().cast<double>());
  std::vector<char> object_sized(regions.count, 0), reaches_outline(regions.count, 0);
  for (int k = 0; k < n; ++k) reaches_outline[regions.region[k]] |= links.on_outline[k];
  int object_sized_count = 0;
  for (int r = 0; r < regions.count; ++r) {
    object_sized[r] = shapes[r].count >= params.min_points && shapes[r].width() >= params.min_part_size_m;
    object_sized_count += object_sized[r];
  }
  if (object_sized_count < 2) return {part};

  // 3. How regions meet: across a boundary (its length), and in space.
  const auto boundary_m = boundary_lengths(links.crossings, regions);
  const auto touching = touching_regions(cloud, part, regions.region, params.cluster_tolerance_m);

  // 4. Join regions.
  auto by_root = join_regions(part, regions.region, regions.count, object_sized, reaches_outline, boundary_m, touching, params);
  if (by_root.size() < 2) return {part};
  return pieces(by_root, part, params.min_points);
}

}  // namespace scenewatch::segmentation
