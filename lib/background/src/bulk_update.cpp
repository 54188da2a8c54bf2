#include "bulk_update.h"

#include <array>

namespace scenewatch::background {

using Node = octomap::ColorOcTreeNode;

octomap::ColorOcTreeNode* BulkColorOcTree::ensure_root(bool& created) {
  created = false;
  if (root == nullptr) {
    root = new Node();
    ++tree_size;
    size_changed = true;
    created = true;
  }
  return root;
}

namespace {
std::uint64_t spread(std::uint64_t v) {
  v &= 0xffff;
  v = (v | (v << 16)) & 0x0000ff0000ffULL;
  v = (v | (v << 8)) & 0x00f00f00f00fULL;
  v = (v | (v << 4)) & 0x0c30c30c30c3ULL;
  v = (v | (v << 2)) & 0x249249249249ULL;
  return v;
}
std::uint64_t compact(std::uint64_t v) {
  v &= 0x249249249249ULL;
  v = (v | (v >> 2)) & 0x0c30c30c30c3ULL;
  v = (v | (v >> 4)) & 0x00f00f00f00fULL;
  v = (v | (v >> 8)) & 0x0000ff0000ffULL;
  v = (v | (v >> 16)) & 0xffff;
  return v;
}

constexpr unsigned kDepth = 16;

struct Descent {
  BulkColorOcTree& tree;
  const std::function<void(const octomap::OcTreeKey&, std::uint8_t[3])>& color_of;
  float hit_log, miss_log, clamp_min, clamp_max;

  void leaf(Node* node, std::uint64_t value) {
    if (value & 1) {
      tree.updateNodeLogOdds(node, hit_log);
      std::uint8_t rgb[3];
      color_of(morton_decode(value >> 1), rgb);
      // ColorOcTree::averageNodeColor, without the second search.
      if (node->isColorSet()) {
        const auto prev = node->getColor();
        node->setColor((prev.r + rgb[0]) / 2, (prev.g + rgb[1]) / 2, (prev.b + rgb[2]) / 2);
      } else {
        node->setColor(rgb[0], rgb[1], rgb[2]);
      }
    } else {
      tree.updateNodeLogOdds(node, miss_log);
    }
  }

  // The updates [b, e) of a node at `level` (unique keys inside its cube) free every voxel of it.
  static bool whole_cube_freed(unsigned level, const std::uint64_t* b, const std::uint64_t* e) {
    if (level == 0 || static_cast<std::uint64_t>(e - b) != std::uint64_t{1} << (3 * (kDepth - level))) return false;
    for (const std::uint64_t* p = b; p < e; ++p)
      if (*p & 1) return false;
    return true;
  }

  void apply(Node* node, unsigned level, const std::uint64_t* b, const std::uint64_t* e, bool fresh) {
    if (level == kDepth) {
      leaf(node, *b);  // keys are unique: one value per leaf
      return;
    }
    const bool leaf_now = fresh || !tree.nodeHasChildren(node);
    if (leaf_now && whole_cube_freed(level, b, e)) {
      // Every voxel of this childless node's cube is freed. OctoMap would create (or expand into)
      // its leaves, each from the node's value, update each by the same miss, and prune them back
      // into this node: the node updated by one miss.
      tree.updateNodeLogOdds(node, miss_log);
      return;
    }
    if (!fresh && leaf_now) {
      // A pruned node above the finest level. OctoMap's updateNode returns early when the node
      // is already clamped in the direction of the update; otherwise it expands the node.
      const float v = node->getLogOdds();
      bool changes = false;
      for (const std::uint64_t* p = b; p < e && !changes; ++p) changes = (*p & 1) ? v < clamp_max : v > clamp_min;
      if (!changes) return;
      tree.expandNode(node);
    }
    const unsigned shift = 1 + 3 * (kDepth - 1 - level);
    for (const std::uint64_t* p = b; p < e;) {
      const unsigned child = static_cast<unsigned>((*p >> shift) & 7);
      const std::uint64_t* q = p + 1;
      while (q < e && ((*q >> shift) & 7) == child) ++q;
      const bool exists = tree.nodeChildExists(node, child);
      Node* c = exists ? tree.getNodeChild(node, child) : tree.createNodeChild(node, child);
      apply(c, level + 1, p, q, !exists);
      p = q;
    }
    // Post-order, as OctoMap's non-lazy update: prune equal children, else refresh the inner node.
    if (level == 0 || !tree.pruneNode(node)) {
      node->updateOccupancyChildren();
      node->updateColorChildren();
    }
  }
};
}  // namespace

namespace {
// spread() of every byte: a 16-bit component is two lookups, not five shift-and-mask steps.
struct SpreadTable {
  std::array<std::uint64_t, 256> byte{};
  SpreadTable() {
    for (std::uint64_t v = 0; v < 256; ++v) byte[v] = spread(v);
  }
};
const SpreadTable kSpread;
std::uint64_t spread16(std::uint64_t v) { return kSpread.byte[v & 0xff] | (kSpread.byte[(v >> 8) & 0xff] << 24); }
}  // namespace

std::uint64_t morton_encode(const octomap::OcTreeKey& k) { return spread16(k[0]) | (spread16(k[1]) << 1) | (spread16(k[2]) << 2); }

octomap::OcTreeKey morton_decode(std::uint64_t c) {
  return octomap::OcTreeKey(static_cast<octomap::key_type>(compact(c)), static_cast<octomap::key_type>(compact(c >> 1)),
                            static_cast<octomap::key_type>(compact(c >> 2)));
}

void radix_sort(std::vector<std::uint64_t>& values, std::vector<std::uint64_t>& scratch, int bits) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  scratch.resize(values.size());
  std::array<std::size_t, kBuckets> count;
  for (int shift = 0; shift < bits; shift += kDigit) {
    count.fill(0);
    for (std::uint64_t v : values) ++count[(v >> shift) & (kBuckets - 1)];
    if (count[(values.empty() ? 0 : (values[0] >> shift) & (kBuckets - 1))] == values.size()) continue;  // one bucket
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t n = c;
      c = sum;
      sum += n;
    }
    for (std::uint64_t v : values) scratch[count[(v >> shift) & (kBuckets - 1)]++] = v;
    values.swap(scratch);
  }
}

void bulk_update(BulkColorOcTree& tree, const std::vector<std::uint64_t>& sorted,
                 const std::function<void(const octomap::OcTreeKey&, std::uint8_t[3])>& color_of) {
  if (sorted.empty()) return;
  bool created = false;
  Node* root = tree.ensure_root(created);
  Descent d{tree, color_of, tree.getProbHitLog(), tree.getProbMissLog(), tree.getClampingThresMinLog(),
            tree.getClampingThresMaxLog()};
  d.apply(root, 0, sorted.data(), sorted.data() + sorted.size(), created);
}

}  // namespace scenewatch::background
