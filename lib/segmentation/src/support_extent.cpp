// Connected part of a support, bridged where the sensor cannot see it: see support_extent.h.
#include "support_extent.h"

#include <tsl/robin_map.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "scenewatch/core/hash.h"

namespace scenewatch::segmentation {
namespace {

std::uint64_t cell_key(long a, long b) {
  return (static_cast<std::uint64_t>(a + (1 << 30)) << 32) | static_cast<std::uint64_t>(b + (1 << 30));
}

// Cells of the plane's grid; inlier cells and hidden (connecting only) cells.
class CellGrid {
 public:
  explicit CellGrid(const PlaneGrid& plane) : plane_(plane) {}
  std::uint64_t key(const Eigen::Vector3d& p) const {
    return cell_key(static_cast<long>(std::floor(p.dot(plane_.u) / plane_.cell_m)),
                    static_cast<long>(std::floor(p.dot(plane_.v) / plane_.cell_m)));
  }
  int add(const Eigen::Vector3d& p) {
    const long a = static_cast<long>(std::floor(p.dot(plane_.u) / plane_.cell_m));
    const long b = static_cast<long>(std::floor(p.dot(plane_.v) / plane_.cell_m));
    auto [it, inserted] = cells_.try_emplace(cell_key(a, b), static_cast<int>(coords_.size()));
    if (inserted) coords_.emplace_back(a, b);
    return it->second;
  }
  std::size_t size() const { return coords_.size(); }
  /// The diagonal of the cells' bounding box, one cell added each way.
  double diagonal_m() const {
    if (coords_.empty()) return 0.0;
    long a0 = coords_[0].first, a1 = a0, b0 = coords_[0].second, b1 = b0;
    for (const auto& [a, b] : coords_) a0 = std::min(a0, a), a1 = std::max(a1, a), b0 = std::min(b0, b), b1 = std::max(b1, b);
    return std::hypot(static_cast<double>(a1 - a0 + 3), static_cast<double>(b1 - b0 + 3)) * plane_.cell_m;
  }
  /// The cell with key k, -1 when there is none.
  int find(std::uint64_t k) const {
    auto it = cells_.find(k);
    return it == cells_.end() ? -1 : it->second;
  }
  /// True when the cell of p or one of its 8 neighbours is in the grid.
  bool near(const Eigen::Vector3d& p) const {
    const long a = static_cast<long>(std::floor(p.dot(plane_.u) / plane_.cell_m));
    const long b = static_cast<long>(std::floor(p.dot(plane_.v) / plane_.cell_m));
    for (long da = -1; da <= 1; ++da)
      for (long db = -1; db <= 1; ++db)
        if (cells_.count(cell_key(a + da, b + db))) return true;
    return false;
  }
  // 8-connected components over all cells.
  std::vector<int> components() const {
    std::vector<int> comp(coords_.size(), -1);
    std::vector<int> stack;
    int ncomp = 0;
    for (std::size_t c = 0; c < coords_.size(); ++c) {
      if (comp[c] >= 0) continue;
      comp[c] = ncomp;
      stack.assign(1, static_cast<int>(c));
      while (!stack.empty()) {
        const int cur = stack.back();
        stack.pop_back();
        for (long da = -1; da <= 1; ++da)
          for (long db = -1; db <= 1; ++db) {
            auto it = cells_.find(cell_key(coords_[cur].first + da, coords_[cur].second + db));
            if (it != cells_.end() && comp[it->second] < 0) {
              comp[it->second] = ncomp;
              stack.push_back(it->second);
            }
          }
      }
      ++ncomp;
    }
    return comp;
  }

 private:
  const PlaneGrid& plane_;
  tsl::robin_map<std::uint64_t, int, MixHash64> cells_;
  std::vector<std::pair<long, long>> coords_;
};

}  // namespace

std::vector<int> support_extent(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& inliers,
                                const PlaneGrid& plane, const std::vector<int>& standing,
                                const std::optional<Eigen::Vector3d>& sensor_origin, double min_height_m,
                                double max_height_m, const std::function<double(double range_m)>& noise_floor_m,
                                std::vector<int>* visible_piece, std::vector<Eigen::Vector3d>* hidden_feet) {
  CellGrid grid(plane);
  std::vector<int> voxel_cell(inliers.size());
  for (std::size_t i = 0; i < inliers.size(); ++i) voxel_cell[i] = grid.add(centroids[inliers[i]].cast<double>());
  // The largest piece in sight, by inliers; one of its cells stands for it (cells added later
  // keep the numbers of those before).
  const std::vector<int> pieces = grid.components();
  std::vector<std::size_t> piece_size(grid.size(), 0);
  for (int c : voxel_cell) ++piece_size[pieces[c]];
  const int largest = static_cast<int>(std::max_element(piece_size.begin(), piece_size.end()) - piece_size.begin());
  const int largest_cell = static_cast<int>(std::find(pieces.begin(), pieces.end(), largest) - pieces.begin());
  // One piece in sight: nothing to bridge.
  const bool in_pieces = std::any_of(pieces.begin(), pieces.end(), [](int c) { return c > 0; });
  std::vector<Eigen::Vector3d> feet;  // of what stands on hidden cells
  if (sensor_origin && in_pieces) {
    const Eigen::Vector3d& o = *sensor_origin;
    const double o_height = plane.n.dot(o) + plane.d;
    std::vector<std::uint64_t> tall_cells;  // cells under something taller than an object
    struct Standing {
      int voxel;
      double h;
      Eigen::Vector3d foot;
      bool on_tall_cell = false;  // something taller than an object stands on its cell too
    };
    std::vector<Standing> pending;
    for (int w : standing) {
      const Eigen::Vector3d q = centroids[w].cast<double>();
      const double h = plane.n.dot(q) + plane.d;
      if (h > max_height_m && h < o_height) tall_cells.push_back(grid.key(q));
      if (h <= min_height_m || h > max_height_m || h >= o_height) continue;
      // Within the sensor's noise of the plane (far floors), a voxel is the plane and hides nothing.
      if (h < noise_floor_m((q - o).norm())) continue;
      pending.push_back({w, h, q - h * plane.n});
    }
    std::sort(tall_cells.begin(), tall_cells.end());
    for (Standing& s : pending) s.on_tall_cell = std::binary_search(tall_cells.begin(), tall_cells.end(), grid.key(s.foot));
    // A shadow longer than the visible plane's extent reaches past every visible cell: the part
    // beyond joins nothing (near the sensor's height, shadows run on for kilometres).
    const double reach_m = grid.diagonal_m();
    // What stands on the visible support hides it: first what stands at a visible cell, then, round
    // by round, what stands on the cells hidden so far (a box behind a box behind a pile), except
    // on a cell that something taller than an object stands on (a wall, a person).
    for (bool first = true; !pending.empty(); first = false) {
      // The highest voxel over each cell hides the most: its shadow covers those of the voxels
      // under it (same foot, shorter shadow the same way).
      tsl::robin_map<std::uint64_t, std::pair<double, int>, MixHash64> highest;
      std::vector<Standing> rest;
      for (const Standing& s : pending) {
        if (!grid.near(s.foot) || (!first && s.on_tall_cell)) {
          rest.push_back(s);
          continue;
        }
        if (!first) feet.push_back(s.foot);
        auto [it, inserted] = highest.try_emplace(grid.key(s.foot), s.h, s.voxel);
        if (!inserted && it->second.first < s.h) it.value() = {s.h, s.voxel};
      }
      if (highest.empty()) break;
      for (const auto& [key, top] : highest) {
        const Eigen::Vector3d q = centroids[top.second].cast<double>();
        const double h = top.first;
        // The ray o + t (q - o) meets the plane at t = o_height / (o_height - h) > 1: behind q.
        const Eigen::Vector3d foot = q - h * plane.n;
        Eigen::Vector3d shadow = o + (o_height / (o_height - h)) * (q - o);
        if ((shadow - foot).norm() > reach_m) shadow = foot + (shadow - foot).normalized() * reach_m;
        const int steps = static_cast<int>(std::ceil((shadow - foot).norm() / plane.cell_m));
        for (int k = 0; k <= steps; ++k) grid.add(foot + (shadow - foot) * (steps ? static_cast<double>(k) / steps : 0.0));
      }
      pending.swap(rest);
    }
  }
  // The support is the largest visible piece and what the hidden cells join to it: bridging
  // extends that piece and never trades it for other pieces joined among themselves. A piece of
  // fewer voxels than plane.min_piece_voxels does not join.
  const std::vector<int> comp = grid.size() == pieces.size() ? pieces : grid.components();
  const int best = comp[largest_cell];
  // What stands on a hidden cell of the support rests on it (a box behind a pile, books running
  // out of the image): the support runs under it.
  if (hidden_feet) {
    hidden_feet->clear();
    for (const Eigen::Vector3d& f : feet) {
      const int c = grid.find(grid.key(f));
      const bool hidden = c >= static_cast<int>(pieces.size());  // cells after the visible ones
      if (hidden && comp[c] == best) hidden_feet->push_back(f);
    }
  }
  std::vector<int> out;
  if (visible_piece) visible_piece->clear();
  for (std::size_t i = 0; i < inliers.size(); ++i) {
    const int piece = pieces[voxel_cell[i]];
    if (comp[voxel_cell[i]] == best && (piece == largest || piece_size[piece] >= plane.min_piece_voxels))
      out.push_back(inliers[i]);
    if (visible_piece && piece == largest) visible_piece->push_back(inliers[i]);
  }
  return out;
}

}  // namespace scenewatch::segmentation
