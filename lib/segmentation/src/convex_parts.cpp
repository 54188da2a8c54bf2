// Local convexity over voxel patches (see convex_parts.h):
//  1. patches: a voxel grid over the cluster; each patch gets a normal (PCA of its points,
//     oriented towards the sensor);
//  2. smooth surfaces: neighbouring patches whose normals agree within the concavity tolerance,
//     unless they are a step (parallel, offset along the normal);
//  3. surfaces join when most links along their border are convex (or only mildly concave, as
//     inside a cup), strongest evidence first, never joining two surfaces whose border is a
//     concave crease; patches too small for a normal join their largest neighbour;
//  4. fragments (parts narrower than an object) are shared out among the parts they touch.
#include "convex_parts.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "apart_sets.h"
#include "part_shape.h"
#include "union_find.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {
namespace {

// Below this many points a patch's normal is noise: 5 points span a plane only barely.
constexpr int kMinPatchPoints = 6;
// A patch of a Kinect at VGA holds about 110 points at 1 m and 50 at 1.5 m; below 20 its normal
// error exceeds the concavity tolerance (sigma sqrt(12) / (L sqrt(N)), see tabletop.h).
constexpr int kDensePatchPoints = 20;

struct Patch {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int points = 0;
  bool has_normal = false;
};

std::vector<Patch> make_patches(const Cloud& cloud, const VoxelIndex& grid, const Eigen::Vector3d& sensor_origin) {
  std::vector<Patch> patches(grid.centroids.size());
  for (std::size_t v = 0; v < patches.size(); ++v) {
    Patch& p = patches[v];
    p.centroid = grid.centroids[v].cast<double>();
    p.points = grid.member_count(static_cast<int>(v));
    if (p.points < kMinPatchPoints) continue;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const int* i = grid.members_begin(static_cast<int>(v)); i != grid.members_end(static_cast<int>(v)); ++i) {
      const Eigen::Vector3d q = cloud[*i].getVector3fMap().cast<double>() - p.centroid;
      cov += q * q.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(cov);
    p.normal = es.eigenvectors().col(0).normalized();
    if (p.normal.dot(sensor_origin - p.centroid) < 0) p.normal = -p.normal;
    p.has_normal = p.normal.allFinite();
  }
  return patches;
}

enum class Link { kSmooth, kConvex, kConcave };

// How two neighbouring patches with normals meet (LCCP's convexity criterion): smooth when their
// normals are within the concavity tolerance and they are not a step (parallel surfaces offset
// along the normal, one in front of the other), else convex or concave.
Link classify(const Patch& a, const Patch& b, const ConvexityParams& params) {
  const Eigen::Vector3d d = a.centroid - b.centroid;
  const double len = d.norm();
  if (len < 1e-9) return Link::kSmooth;
  const Eigen::Vector3d u = d / len;
  const double cos_angle = std::clamp(a.normal.dot(b.normal), -1.0, 1.0);
  if (cos_angle >= std::cos(params.concavity_tolerance_deg * M_PI / 180.0)) {
    const Eigen::Vector3d mean_normal = (a.normal + b.normal).normalized();
    return std::abs(u.dot(mean_normal)) <= params.max_step_ratio ? Link::kSmooth : Link::kConcave;
  }
  if ((a.normal - b.normal).dot(u) > 0.0) return Link::kConvex;
  // A mild concavity is the curved inside of a cup or a bowl, not a crease between two objects.
  return cos_angle >= std::cos(params.crease_angle_deg * M_PI / 180.0) ? Link::kConvex : Link::kConcave;
}

}  // namespace

std::vector<std::vector<int>> split_at_concavities(const Cloud& cloud, const std::vector<int>& cluster,
                                                   const Eigen::Vector3d& sensor_origin, const ConvexityParams& params) {
  const VoxelIndex grid(cloud, cluster, params.patch_size_m);
  const std::vector<Patch> patches = make_patches(cloud, grid, sensor_origin);
  const int n = static_cast<int>(patches.size());
  // Too sparse to judge convexity (a far or low-resolution view): most points must lie in patches
  // dense enough for a steady normal, else there is no evidence of a crease.
  std::size_t in_dense = 0;
  for (const Patch& p : patches) in_dense += p.points >= kDensePatchPoints ? p.points : 0;
  if (2 * in_dense < cluster.size()) return {cluster};
  std::vector<std::pair<int, int>> adjacent;
  for (int v = 0; v < n; ++v) {
    const auto& c = grid.coords[v];
    for (const auto& o : forward_offsets()) {
      const int w = grid.find(c[0] + o[0], c[1] + o[1], c[2] + o[2]);
      if (w >= 0) adjacent.emplace_back(v, w);
    }
  }

  // Smooth surfaces first (faces of a box, the body of a bowl); then neighbouring surfaces are
  // one object when most patch links along their common border are convex. One noisy link
  // (a patch straddling a crease) cannot join two objects, as it would in a plain union.
  std::vector<Link> links(adjacent.size(), Link::kConcave);
  UnionFind patch_uf(n);
  for (std::size_t e = 0; e < adjacent.size(); ++e) {
    const auto [a, b] = adjacent[e];
    if (!patches[a].has_normal || !patches[b].has_normal) continue;
    links[e] = classify(patches[a], patches[b], params);
    if (links[e] == Link::kSmooth) patch_uf.unite(a, b);
  }
  std::map<std::pair<int, int>, std::pair<int, int>> votes;  // (convex, concave) per surface pair
  for (std::size_t e = 0; e < adjacent.size(); ++e) {
    const auto [a, b] = adjacent[e];
    if (!patches[a].has_normal || !patches[b].has_normal) continue;
    const int ra = patch_uf.find(a), rb = patch_uf.find(b);
    if (ra == rb) continue;
    auto& v = votes[{std::min(ra, rb), std::max(ra, rb)}];
    (links[e] == Link::kConcave ? v.second : v.first) += 1;
  }
  // Surfaces whose border is mostly concave are never one object, not even through a third
  // surface convex to both (a patch row straddling the crease): merges go strongest first and
  // skip any that would join such a pair.
  std::vector<std::pair<std::pair<int, int>, std::pair<int, int>>> ranked(votes.begin(), votes.end());
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.second.first > y.second.first; });
  ApartSets apart;
  for (const auto& [pair, v] : ranked) {
    if (v.second >= v.first) {
      apart[pair.first].insert(pair.second);
      apart[pair.second].insert(pair.first);
    }
  }
  for (const auto& [pair, v] : ranked) {
    if (v.first > v.second) unite_unless_apart(patch_uf, apart, pair.first, pair.second);
  }
  // Patches without a normal take the part of their largest neighbour with one.
  std::vector<int> best_neighbour(n, -1);
  for (const auto& [a, b] : adjacent) {
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      if (patches[x].has_normal || !patches[y].has_normal) continue;
      if (best_neighbour[x] < 0 || patches[y].points > patches[best_neighbour[x]].points) best_neighbour[x] = y;
    }
  }
  for (int v = 0; v < n; ++v) {
    if (best_neighbour[v] >= 0) patch_uf.unite(v, best_neighbour[v]);
  }

  // Fragments: parts narrower than an object can be (a row of patches straddling a crease, a
  // noisy rim). Their patches are given, patch by patch, to the neighbouring real part they
  // touch most, so a crease row is shared out between the two objects it separates.
  std::vector<int> label(n);
  for (int v = 0; v < n; ++v) label[v] = patch_uf.find(v);
  std::map<int, PartShape> shapes;
  for (int v = 0; v < n; ++v) {
    for (const int* i = grid.members_begin(v); i != grid.members_end(v); ++i) shapes[label[v]].add(cloud[*i].getVector3fMap().cast<double>());
  }
  std::map<int, bool> wide;  // per part, one eigen-solve
  for (const auto& [part, shape] : shapes) wide[part] = shape.width() >= params.min_part_size_m;
  std::vector<int> owner(n, -1);
  for (int v = 0; v < n; ++v) {
    if (wide[label[v]]) owner[v] = label[v];
  }
  std::vector<std::vector<int>> neighbours(n);
  for (const auto& [a, b] : adjacent) {
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  for (bool changed = true; changed;) {
    changed = false;
    const std::vector<int> before = owner;
    for (int v = 0; v < n; ++v) {
      if (before[v] >= 0) continue;
      std::map<int, int> votes_for;
      for (int w : neighbours[v]) {
        if (before[w] >= 0) ++votes_for[before[w]];
      }
      int best = -1, best_votes = 0;
      for (const auto& [part, count] : votes_for) {
        if (count > best_votes) best = part, best_votes = count;
      }
      if (best >= 0) owner[v] = best, changed = true;
    }
  }
  for (int v = 0; v < n; ++v) {
    if (owner[v] < 0) owner[v] = label[v];  // an isolated fragment stays what it is
  }

  std::map<int, std::vector<int>> by_part;
  for (int v = 0; v < n; ++v) {
    auto& out = by_part[owner[v]];
    out.insert(out.end(), grid.members_begin(v), grid.members_end(v));
  }
  std::vector<std::vector<int>> result;
  result.reserve(by_part.size());
  for (auto& [root, indices] : by_part) {
    std::sort(indices.begin(), indices.end());
    result.push_back(std::move(indices));
  }
  return result;
}

}  // namespace scenewatch::segmentation
