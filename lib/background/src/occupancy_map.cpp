// The background occupancy map over OctoMap's ColorOcTree.
//
// Fast insertion follows OctoMap's own discretized update (OccupancyOcTreeBase::computeDiscreteUpdate):
// endpoints are first reduced to one per voxel, rays are cast from the sensor to the voxel centres,
// and cells both hit and passed through count as hit (frame_trace.h). The voxels live in blocks
// of 8x8x8 bits (ray_set.h), which are applied in Morton order in one descent of the tree
// (bulk_update.h), which also refreshes inner nodes along the touched paths only.
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "bulk_update.h"
#include "frame_trace.h"
#include "octree_file_check.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/files.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::background {
namespace fs = std::filesystem;

namespace {

using octomap::OcTreeKey;

// ColorOcTree::updateInnerOccupancy() dereferences the root without checking it (OctoMap 1.9.7):
// on an empty tree it crashes.
void refresh_inner(octomap::ColorOcTree& tree) {
  if (tree.getRoot() != nullptr) tree.updateInnerOccupancy();
}

}  // namespace

struct OccupancyMap::Impl {
  explicit Impl(const Config& c) : tree(c.resolution_m) { apply(c); }
  void apply(const Config& c) {
    tree.setProbHit(c.prob_hit);
    tree.setProbMiss(c.prob_miss);
    tree.setClampingThresMin(c.clamp_min);
    tree.setClampingThresMax(c.clamp_max);
  }
  BulkColorOcTree tree;
  // The last insert's endpoints (with their colour) and ray voxels, kept for
  // freed_by_last_insert(); scratch buffers reused between frames.
  FrameTrace trace;
  std::vector<std::uint64_t> order, scratch;
};

Status validate(const Config& c) {
  auto bad = [](const std::string& key, const std::string& why) { return invalid_argument("background." + key + ": " + why); };
  if (!(c.resolution_m >= 0.001 && c.resolution_m <= 1.0)) return bad("resolution_m", "must be in [0.001, 1] m, got " + std::to_string(c.resolution_m));
  if (!std::isfinite(c.max_range_m)) return bad("max_range_m", "must be finite");
  if (!(c.prob_hit > 0.5 && c.prob_hit < 1.0)) return bad("prob_hit", "must be in (0.5, 1), got " + std::to_string(c.prob_hit));
  if (!(c.prob_miss > 0.0 && c.prob_miss < 0.5)) return bad("prob_miss", "must be in (0, 0.5), got " + std::to_string(c.prob_miss));
  if (!(c.clamp_min > 0.0 && c.clamp_min < 0.5)) return bad("clamp_min", "must be in (0, 0.5), got " + std::to_string(c.clamp_min));
  if (!(c.clamp_max > 0.5 && c.clamp_max < 1.0)) return bad("clamp_max", "must be in (0.5, 1), got " + std::to_string(c.clamp_max));
  if (c.ray_stop_after < 0 || c.ray_stop_after > 1000) return bad("ray_stop_after", "must be in [0, 1000], got " + std::to_string(c.ray_stop_after));
  if (c.insert_stride_px < 1 || c.insert_stride_px > 8) return bad("insert_stride_px", "must be in [1, 8], got " + std::to_string(c.insert_stride_px));
  return {};
}

const char* to_string(Occupancy o) {
  switch (o) {
    case Occupancy::kUnknown: return "unknown";
    case Occupancy::kFree: return "free";
    case Occupancy::kOccupied: return "occupied";
  }
  return "unknown";
}

OccupancyMap::OccupancyMap(const Config& config) : config_(config), impl_(std::make_unique<Impl>(config)) {}
OccupancyMap::~OccupancyMap() = default;
OccupancyMap::OccupancyMap(OccupancyMap&&) noexcept = default;
OccupancyMap& OccupancyMap::operator=(OccupancyMap&&) noexcept = default;

namespace {
// Reference: OctoMap's plain insertion, one ray per point. The key sets OctoMap computes inside
// insertPointCloud are kept in `rays` for freed_by_last_insert().
InsertStats insert_plain(octomap::ColorOcTree& tree, const Cloud& points_camera, const Eigen::Isometry3f& T, double max_range,
                         RaySet& rays) {
  InsertStats stats;
  const octomap::point3d origin(T.translation().x(), T.translation().y(), T.translation().z());
  OcTreeKey origin_key;
  if (!tree.coordToKeyChecked(origin, origin_key)) {
    rays.reset(OcTreeKey(0, 0, 0), OcTreeKey(0, 0, 0));
    return stats;  // the sensor is outside the map's extent
  }
  octomap::Pointcloud scan;
  scan.reserve(points_camera.size());
  for (const auto& p : points_camera.points) {
    if (!is_valid(p)) continue;
    const Eigen::Vector3f w = T * p.getVector3fMap();
    scan.push_back(w.x(), w.y(), w.z());
  }
  stats.points = scan.size();
  const double range = max_range > 0 ? max_range : -1.0;
  octomap::KeySet free_keys, occupied_keys;
  tree.computeUpdate(scan, origin, free_keys, occupied_keys, range);
  OcTreeKey lo = origin_key, hi = origin_key;
  for (const auto* keys : {&free_keys, &occupied_keys}) {
    for (const auto& k : *keys) {
      for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], k[i]), hi[i] = std::max(hi[i], k[i]);
    }
  }
  rays.reset(lo, hi);
  for (const auto& k : free_keys) rays.insert_free(k);
  for (const auto& k : occupied_keys) rays.insert_end(k);
  stats.free_updates = free_keys.size();
  stats.occupied_updates = occupied_keys.size();
  tree.insertPointCloud(scan, origin, range, /*lazy_eval=*/false, /*discretize=*/false);
  for (const auto& p : points_camera.points) {
    if (!is_valid(p)) continue;
    const Eigen::Vector3f w = T * p.getVector3fMap();
    tree.averageNodeColor(w.x(), w.y(), w.z(), p.r, p.g, p.b);
  }
  return stats;
}
}  // namespace

InsertStats OccupancyMap::insert(const Cloud& points_camera, const Pose& T_world_camera, int stride) {
  auto& tree = impl_->tree;
  auto& trace = impl_->trace;
  const Eigen::Isometry3f T = T_world_camera.cast<float>();
  if (!config_.fast_insertion) return insert_plain(tree, points_camera, T, config_.max_range_m, trace.rays());

  // 1. The frame's endpoints and rays (frame_trace.h).
  InsertStats stats;
  TraceSettings settings;
  settings.max_range_m = config_.max_range_m;
  settings.ray_stop_after = config_.ray_stop_after;
  settings.stride = stride;
  stats.points = trace.trace(tree, points_camera, T, settings);
  auto& rays = trace.rays();

  // 2. One ordered descent of the tree, block by block in Morton order.
  stats.free_updates = rays.count_freed();
  stats.occupied_updates = rays.count_ends();
  rays.morton_order(impl_->order, impl_->scratch);
  bulk_update(tree, rays, impl_->order,
              [&](const OcTreeKey& k, std::uint8_t rgb[3]) { trace.endpoints().mean_color_in_order(k, rgb); });
  return stats;
}

Occupancy OccupancyMap::query(const Eigen::Vector3d& p) const {
  if (!p.allFinite()) return Occupancy::kUnknown;
  OcTreeKey key;
  const auto& tree = impl_->tree;
  if (!tree.coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) return Occupancy::kUnknown;
  const auto* node = tree.search(key);
  if (node == nullptr) return Occupancy::kUnknown;
  return tree.isNodeOccupied(node) ? Occupancy::kOccupied : Occupancy::kFree;
}

bool OccupancyMap::freed_by_last_insert(const Eigen::Vector3d& p) const {
  OcTreeKey key;
  if (!p.allFinite() || !impl_->tree.coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) return false;
  return impl_->trace.rays().freed(key);
}

namespace {
// Finest-level key range [lo, hi] (inclusive) of the voxels a box overlaps; a face lying on a voxel
// boundary does not take in the voxel beyond it. Computed in double: point3d is float, whose
// rounding would move boundaries by a voxel.
bool key_range(const octomap::ColorOcTree& tree, const Aabb& box, OcTreeKey& lo, OcTreeKey& hi) {
  const double eps = 1e-6 * tree.getResolution();
  for (int i = 0; i < 3; ++i) {
    if (!tree.coordToKeyChecked(box.min(i) + eps, lo[i]) || !tree.coordToKeyChecked(box.max(i) - eps, hi[i])) return false;
  }
  return true;
}

// Number of finest voxels of a leaf (centre c, edge `size`) whose keys lie in [lo, hi].
std::size_t overlap_voxels(const octomap::ColorOcTree& tree, const octomap::point3d& c, double size,
                           const OcTreeKey& lo, const OcTreeKey& hi) {
  const double res = tree.getResolution();
  std::size_t count = 1;
  for (int i = 0; i < 3; ++i) {
    const long first = tree.coordToKey(c(i) - size / 2 + res / 2);
    const long last = tree.coordToKey(c(i) + size / 2 - res / 2);
    const long a = std::max<long>(first, lo[i]), b = std::min<long>(last, hi[i]);
    if (b < a) return 0;
    count *= static_cast<std::size_t>(b - a + 1);
  }
  return count;
}
}  // namespace

BoxOccupancy OccupancyMap::query_box(const Aabb& box) const {
  BoxOccupancy out;
  const auto& tree = impl_->tree;
  OcTreeKey lo, hi;
  if (!box.valid() || !key_range(tree, box, lo, hi)) return out;
  std::size_t total = 1;
  for (int i = 0; i < 3; ++i) total *= static_cast<std::size_t>(hi[i] - lo[i] + 1);
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    const std::size_t n = overlap_voxels(tree, it.getCoordinate(), it.getSize(), lo, hi);
    (tree.isNodeOccupied(*it) ? out.occupied_voxels : out.free_voxels) += n;
  }
  out.unknown_voxels = total - std::min(total, out.occupied_voxels + out.free_voxels);
  out.state = out.occupied_voxels > 0 ? Occupancy::kOccupied
              : out.unknown_voxels > 0 ? Occupancy::kUnknown
                                       : Occupancy::kFree;
  return out;
}

std::size_t OccupancyMap::clear_box(const Aabb& box) {
  auto& tree = impl_->tree;
  OcTreeKey lo, hi;
  if (!box.valid() || !key_range(tree, box, lo, hi)) return 0;
  const float free_log = tree.getClampingThresMinLog();
  const double res = tree.getResolution();
  std::size_t changed = 0;
  // A leaf wholly inside the box is set as it is, however coarse; only leaves that straddle a face
  // of the box are visited voxel by voxel, so memory stays bounded by the box's surface, not its
  // volume. Keys are collected first: changing the tree while iterating would invalidate the
  // iterator.
  std::vector<OcTreeKey> keys;
  for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
    const octomap::point3d c = it.getCoordinate();
    const double size = it.getSize();
    long first[3], last[3];
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
      first[i] = tree.coordToKey(c(i) - size / 2 + res / 2);
      last[i] = tree.coordToKey(c(i) + size / 2 - res / 2);
      inside = inside && first[i] >= lo[i] && last[i] <= hi[i];
    }
    if (inside) {
      it->setLogOdds(free_log);
      changed += static_cast<std::size_t>(last[0] - first[0] + 1) * (last[1] - first[1] + 1) * (last[2] - first[2] + 1);
      continue;
    }
    OcTreeKey k;
    for (long x = std::max<long>(first[0], lo[0]); x <= std::min<long>(last[0], hi[0]); ++x)
      for (long y = std::max<long>(first[1], lo[1]); y <= std::min<long>(last[1], hi[1]); ++y)
        for (long z = std::max<long>(first[2], lo[2]); z <= std::min<long>(last[2], hi[2]); ++z) {
          k[0] = static_cast<octomap::key_type>(x);
          k[1] = static_cast<octomap::key_type>(y);
          k[2] = static_cast<octomap::key_type>(z);
          keys.push_back(k);
        }
  }
  for (const auto& k : keys) tree.setNodeValue(k, free_log, /*lazy_eval=*/true);
  refresh_inner(tree);
  return changed + keys.size();
}

namespace {

// Copies the leaves of the tree that overlap the key box [lo, hi] into a dense grid, by one
// recursive descent with integer key ranges (a node at level L spans 2^(depth-L) keys per axis;
// child bit 0 is the upper half in x, bit 1 in y, bit 2 in z, as OctoMap's computeChildIdx).
// About 3x faster than OctoMap's leaf_bbx_iterator, which computes every leaf's centre in floats.
struct GridFill {
  const BulkColorOcTree& tree;
  OcTreeKey lo, hi;
  unsigned depth;
  DenseGrid& grid;
  bool uncertain_free = false;  // list the free voxels not yet at the lower clamp

  void visit(const octomap::ColorOcTreeNode* node, unsigned level, const std::array<unsigned, 3>& base) {
    const unsigned span = 1u << (depth - level);
    for (int i = 0; i < 3; ++i) {
      if (base[i] > hi[i] || base[i] + span - 1 < lo[i]) return;
    }
    if (level == depth || !tree.nodeHasChildren(node)) {
      fill(*node, base, span);
      return;
    }
    const unsigned half = span / 2;
    for (unsigned c = 0; c < 8; ++c) {
      if (!tree.nodeChildExists(node, c)) continue;
      const std::array<unsigned, 3> child{base[0] + ((c & 1) ? half : 0), base[1] + ((c & 2) ? half : 0),
                                          base[2] + ((c & 4) ? half : 0)};
      visit(tree.getNodeChild(node, c), level + 1, child);
    }
  }

  void fill(const octomap::ColorOcTreeNode& node, const std::array<unsigned, 3>& base, unsigned span) {
    if (span == 1) {  // most leaves are single voxels (visit() has checked that this one is in the box)
      fill_voxel(node, (static_cast<std::size_t>(base[2] - lo[2]) * grid.ny + (base[1] - lo[1])) * grid.nx + (base[0] - lo[0]));
      return;
    }
    long first[3], last[3];
    for (int i = 0; i < 3; ++i) {
      first[i] = std::max<long>(base[i], lo[i]) - lo[i];
      last[i] = std::min<long>(base[i] + span - 1, hi[i]) - lo[i];
    }
    const bool occupied = tree.isNodeOccupied(node);
    const auto s = static_cast<std::uint8_t>(occupied ? Occupancy::kOccupied : Occupancy::kFree);
    // Each row of the leaf's voxels in the box gets the state, then `also(row)`.
    const auto rows = [&](const auto& also) {
      for (long z = first[2]; z <= last[2]; ++z)
        for (long y = first[1]; y <= last[1]; ++y) {
          const std::size_t row = (static_cast<std::size_t>(z) * grid.ny + y) * grid.nx;
          std::fill(grid.state.begin() + row + first[0], grid.state.begin() + row + last[0] + 1, s);
          also(row);
        }
    };
    if (!occupied && !uncertain_free) {  // the common case, free space: the state alone
      rows([](std::size_t) {});
      return;
    }
    DenseGrid::Surface surface;
    std::vector<DenseGrid::Surface>* listed = list_for(node, occupied, surface);
    rows([&](std::size_t row) {
      if (listed == nullptr) return;
      for (long x = first[0]; x <= last[0]; ++x) {
        surface.index = row + x;
        listed->push_back(surface);
      }
    });
  }

  // fill() for one voxel, at its index in the grid.
  void fill_voxel(const octomap::ColorOcTreeNode& node, std::size_t index) {
    const bool occupied = tree.isNodeOccupied(node);
    grid.state[index] = static_cast<std::uint8_t>(occupied ? Occupancy::kOccupied : Occupancy::kFree);
    if (!occupied && !uncertain_free) return;
    DenseGrid::Surface surface;
    if (std::vector<DenseGrid::Surface>* listed = list_for(node, occupied, surface)) {
      surface.index = index;
      listed->push_back(surface);
    }
  }

  // The list a leaf's voxels go in (nullptr: none), and their entry there but for the index.
  std::vector<DenseGrid::Surface>* list_for(const octomap::ColorOcTreeNode& node, bool occupied, DenseGrid::Surface& surface) const {
    // OctoMap clamps a belief exactly at the bound (and set_voxels writes the bound itself).
    std::vector<DenseGrid::Surface>* listed =
        occupied ? &grid.occupied
                 : (uncertain_free && node.getLogOdds() > tree.getClampingThresMinLog() ? &grid.uncertain_free : nullptr);
    if (listed != nullptr) surface.probability = static_cast<std::uint8_t>(std::lround(255.0 * node.getOccupancy()));
    if (occupied) {
      const octomap::ColorOcTreeNode::Color col = node.getColor();
      surface.rgb = (std::uint32_t{col.r} << 16) | (std::uint32_t{col.g} << 8) | col.b;
    }
    return listed;
  }
};

}  // namespace

Result<DenseGrid> OccupancyMap::dense_grid(const Aabb& box, std::size_t max_voxels) const {
  DenseGrid grid;
  if (auto st = fill_dense_grid(box, grid, max_voxels, /*with_uncertain_free=*/true); !st) return st.error();
  return grid;
}

Status OccupancyMap::fill_dense_grid(const Aabb& box, DenseGrid& grid, std::size_t max_voxels, bool with_uncertain_free) const {
  const auto& tree = impl_->tree;
  OcTreeKey lo, hi;
  if (!box.valid()) return invalid_argument("dense grid: the box is empty or not finite");
  if (!key_range(tree, box, lo, hi)) return invalid_argument("dense grid: the box leaves the map's extent");
  const std::size_t n = static_cast<std::size_t>(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
  if (n > max_voxels) {
    return invalid_argument("dense grid: the box holds " + std::to_string(n) + " voxels, more than " +
                            std::to_string(max_voxels));
  }
  grid.resolution = tree.getResolution();
  grid.nx = hi[0] - lo[0] + 1;
  grid.ny = hi[1] - lo[1] + 1;
  grid.nz = hi[2] - lo[2] + 1;
  const double res = grid.resolution;
  grid.origin = Eigen::Vector3d(tree.keyToCoord(lo[0]), tree.keyToCoord(lo[1]), tree.keyToCoord(lo[2])) -
                Eigen::Vector3d::Constant(res / 2);
  // assign() and clear() keep the buffers of a grid filled before: no fresh pages per frame.
  grid.state.assign(n, static_cast<std::uint8_t>(Occupancy::kUnknown));
  grid.occupied.clear();
  grid.uncertain_free.clear();
  if (tree.getRoot() != nullptr) {
    GridFill fill{tree, lo, hi, tree.getTreeDepth(), grid, with_uncertain_free};
    fill.visit(tree.getRoot(), 0, {0u, 0u, 0u});
  }
  const auto by_index = [](const DenseGrid::Surface& a, const DenseGrid::Surface& b) { return a.index < b.index; };
  std::sort(grid.occupied.begin(), grid.occupied.end(), by_index);
  std::sort(grid.uncertain_free.begin(), grid.uncertain_free.end(), by_index);
  return {};
}

std::size_t OccupancyMap::set_voxels(const std::vector<Eigen::Vector3d>& points, Occupancy state) {
  auto& tree = impl_->tree;
  std::vector<std::uint64_t> keys;
  keys.reserve(points.size());
  OcTreeKey key;
  for (const auto& p : points) {
    if (p.allFinite() && tree.coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) keys.push_back(pack_key(key));
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  const float log_odds = state == Occupancy::kOccupied ? tree.getClampingThresMaxLog() : tree.getClampingThresMinLog();
  for (std::uint64_t k : keys) {
    if (state == Occupancy::kUnknown) {
      tree.deleteNode(unpack_key(k));
    } else {
      tree.setNodeValue(unpack_key(k), log_odds, /*lazy_eval=*/true);
    }
  }
  if (state != Occupancy::kUnknown) refresh_inner(tree);
  return keys.size();
}

void OccupancyMap::reset() {
  impl_->tree.clear();
  impl_->trace.clear();
}

Status OccupancyMap::save(const fs::path& path) const {
  std::string ext = path.extension().string();
  if (ext != ".ot" && ext != ".bt") return invalid_argument(quoted(path) + ": map files end in .ot or .bt");
  return write_atomically(path, [&](const fs::path& tmp) -> Status {
    return with_system_reason([&]() -> Status {
      std::ofstream out(tmp, std::ios::binary);
      if (!out) return io_error(quoted(tmp) + ": cannot open for writing");
      bool ok = ext == ".ot" ? impl_->tree.write(out) : impl_->tree.writeBinaryConst(out);
      out.flush();
      ok = ok && static_cast<bool>(out);
      if (!ok) return io_error(quoted(path) + ": writing the map failed");
      return {};
    });
  });
}

Status OccupancyMap::load(const fs::path& path) {
  if (auto st = check_readable_file(path); !st) return st;
  if (auto st = check_octree_file(path); !st) return st;  // before OctoMap's unbounded recursion
  const std::string ext = path.extension().string();
  auto loaded = std::make_unique<Impl>(config_);
  if (ext == ".bt") {
    std::ifstream in(path, std::ios::binary);
    if (!loaded->tree.readBinary(in)) return invalid_argument(quoted(path) + ": not a valid OctoMap binary (.bt) file");
  } else if (ext == ".ot") {
    std::ifstream in(path, std::ios::binary);
    std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(in));
    if (!tree) return invalid_argument(quoted(path) + ": not a valid OctoMap (.ot) file");
    if (auto* color = dynamic_cast<octomap::ColorOcTree*>(tree.get())) {
      // swapContent swaps the node structure only; the metadata must match first.
      loaded->tree.setResolution(color->getResolution());
      loaded->tree.swapContent(*color);
    } else if (auto* plain = dynamic_cast<octomap::OcTree*>(tree.get())) {
      loaded->tree.setResolution(plain->getResolution());
      for (auto it = plain->begin_leafs(), end = plain->end_leafs(); it != end; ++it) {
        loaded->tree.setNodeValue(it.getKey(), it->getLogOdds(), true);
      }
      refresh_inner(loaded->tree);
    } else {
      return invalid_argument(quoted(path) + ": holds a " + tree->getTreeType() + ", not an occupancy tree");
    }
  } else {
    return invalid_argument(quoted(path) + ": map files end in .ot or .bt");
  }
  config_.resolution_m = loaded->tree.getResolution();
  loaded->apply(config_);
  impl_ = std::move(loaded);
  return {};
}

double OccupancyMap::resolution() const { return impl_->tree.getResolution(); }
std::size_t OccupancyMap::num_leaf_nodes() const { return impl_->tree.getNumLeafNodes(); }

std::string OccupancyMap::binary_data() const {
  // ColorOcTree and OcTree share the binary format (two bits per child), so an OcTree reads it.
  std::ostringstream out(std::ios::binary);
  impl_->tree.writeBinaryData(out);
  return std::move(out).str();
}

std::size_t OccupancyMap::num_nodes() const { return impl_->tree.size(); }
std::size_t OccupancyMap::memory_bytes() const { return impl_->tree.memoryUsage(); }

std::size_t OccupancyMap::num_occupied_leaves() const {
  std::size_t n = 0;
  const auto& tree = impl_->tree;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) n += tree.isNodeOccupied(*it) ? 1 : 0;
  return n;
}

std::vector<Eigen::Vector3d> OccupancyMap::occupied_voxel_centers() const {
  std::vector<Eigen::Vector3d> out;
  const auto& tree = impl_->tree;
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::lround(size / res)));
    for (int x = 0; x < n; ++x)
      for (int y = 0; y < n; ++y)
        for (int z = 0; z < n; ++z) {
          out.emplace_back(c.x() - size / 2 + (x + 0.5) * res, c.y() - size / 2 + (y + 0.5) * res,
                           c.z() - size / 2 + (z + 0.5) * res);
        }
  }
  return out;
}

}  // namespace scenewatch::background
