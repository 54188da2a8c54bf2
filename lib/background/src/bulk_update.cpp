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
constexpr unsigned kBlockLevel = kDepth - RaySet::kBlockLevels;  // the level of a block's node
using Block = RaySet::Block;

// What a node's updates hold: every voxel of its cube freed, any hit, any miss.
struct Summary {
  bool all_freed = true, any_hit = false, any_miss = false;
};

// The updates of the voxels [first, first + n) of a block, in its Morton order (n = 512, 64 or 8:
// the cube of a node at the block's level or one or two below it).
// The bits of [first, first + n) within their word (n < 64 stays inside one word).
std::uint64_t span_mask(unsigned first, unsigned n) {
  return n >= 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << n) - 1) << (first & 63);
}

Summary summarise(const Block& block, unsigned first, unsigned n) {
  Summary s;
  const std::uint64_t mask = span_mask(first, n);
  for (unsigned w = first >> 6; w < ((first + n + 63) >> 6); ++w) {
    const std::uint64_t hit = block.end[w] & mask, miss = block.free[w] & ~block.end[w] & mask;
    s.all_freed = s.all_freed && miss == mask;
    s.any_hit = s.any_hit || hit != 0;
    s.any_miss = s.any_miss || miss != 0;
  }
  return s;
}

// Whether any voxel of [first, first + n) is updated.
bool touched(const Block& block, unsigned first, unsigned n) {
  const std::uint64_t mask = span_mask(first, n);
  for (unsigned w = first >> 6; w < ((first + n + 63) >> 6); ++w)
    if ((block.free[w] | block.end[w]) & mask) return true;
  return false;
}

struct Descent {
  BulkColorOcTree& tree;
  const std::vector<Block>& blocks;
  const std::function<void(const octomap::OcTreeKey&, std::uint8_t[3])>& color_of;
  float hit_log, miss_log, clamp_min, clamp_max;

  void leaf(Node* node, bool hit, std::uint64_t code) {
    if (!hit) {
      tree.updateNodeLogOdds(node, miss_log);
      return;
    }
    tree.updateNodeLogOdds(node, hit_log);
    std::uint8_t rgb[3];
    color_of(morton_decode(code), rgb);
    // ColorOcTree::averageNodeColor, without the second search.
    if (node->isColorSet()) {
      const auto prev = node->getColor();
      node->setColor((prev.r + rgb[0]) / 2, (prev.g + rgb[1]) / 2, (prev.b + rgb[2]) / 2);
    } else {
      node->setColor(rgb[0], rgb[1], rgb[2]);
    }
  }

  // A node without children (fresh, or pruned above the finest level) whose updates need no
  // descent: true when it is done. `summary` is asked only for childless nodes.
  template <typename GetSummary>
  bool settled_childless(Node* node, unsigned level, bool fresh, GetSummary summary) {
    if (!fresh && tree.nodeHasChildren(node)) return false;
    const Summary s = summary();
    if (level > 0 && s.all_freed) {
      // Every voxel of this childless node's cube is freed. OctoMap would create (or expand into)
      // its leaves, each from the node's value, update each by the same miss, and prune them back
      // into this node: the node updated by one miss.
      tree.updateNodeLogOdds(node, miss_log);
      return true;
    }
    if (!fresh) {
      // A pruned node above the finest level. OctoMap's updateNode returns early when the node
      // is already clamped in the direction of the update; otherwise it expands the node.
      const float v = node->getLogOdds();
      if (!((s.any_hit && v < clamp_max) || (s.any_miss && v > clamp_min))) return true;
      tree.expandNode(node);
    }
    return false;
  }

  Node* child(Node* node, unsigned c, bool& fresh) {
    fresh = !tree.nodeChildExists(node, c);
    return fresh ? tree.createNodeChild(node, c) : tree.getNodeChild(node, c);
  }

  // Post-order, as OctoMap's non-lazy update: prune equal children, else refresh the inner node.
  void finish(Node* node, unsigned level) {
    if (level == 0 || !tree.pruneNode(node)) {
      node->updateOccupancyChildren();
      node->updateColorChildren();
    }
  }

  static std::uint64_t code(std::uint64_t ordered) { return ordered >> RaySet::kNumberBits; }
  const Block& block(std::uint64_t ordered) const {
    return blocks[ordered & ((std::uint64_t{1} << RaySet::kNumberBits) - 1)];
  }

  // Levels above the blocks: [b, e) are the blocks inside this node's cube, in Morton order
  // (RaySet::morton_order).
  void above_blocks(Node* node, unsigned level, const std::uint64_t* b, const std::uint64_t* e, bool fresh) {
    if (level == kBlockLevel) {
      in_block(node, level, block(*b), code(*b), 0, fresh);  // one block per node of the block level
      return;
    }
    const bool settled = settled_childless(node, level, fresh, [&] {
      Summary s;
      s.all_freed = static_cast<std::uint64_t>(e - b) == std::uint64_t{1} << (3 * (kBlockLevel - level));
      for (const std::uint64_t* p = b; p < e; ++p) {
        const Summary one = summarise(block(*p), 0, RaySet::kBlockVoxels);
        s.all_freed = s.all_freed && one.all_freed;
        s.any_hit = s.any_hit || one.any_hit;
        s.any_miss = s.any_miss || one.any_miss;
      }
      return s;
    });
    if (settled) return;
    const unsigned shift = 3 * (kBlockLevel - 1 - level);
    for (const std::uint64_t* p = b; p < e;) {
      const unsigned c = static_cast<unsigned>((code(*p) >> shift) & 7);
      const std::uint64_t* q = p + 1;
      while (q < e && ((code(*q) >> shift) & 7) == c) ++q;
      bool child_fresh = false;
      Node* n = child(node, c, child_fresh);
      above_blocks(n, level + 1, p, q, child_fresh);
      p = q;
    }
    finish(node, level);
  }

  // Inside a block: this node's cube is the block's voxels [first, first + 8^(16 - level)).
  void in_block(Node* node, unsigned level, const Block& block, std::uint64_t block_code, unsigned first, bool fresh) {
    if (level == kDepth) {
      leaf(node, (block.end[first >> 6] >> (first & 63)) & 1, (block_code << (3 * RaySet::kBlockLevels)) | first);
      return;
    }
    const unsigned n = 1u << (3 * (kDepth - level));
    if (settled_childless(node, level, fresh, [&] { return summarise(block, first, n); })) return;
    const unsigned part = n / 8;
    for (unsigned c = 0; c < 8; ++c) {
      const unsigned sub = first + c * part;
      if (!touched(block, sub, part)) continue;
      bool child_fresh = false;
      Node* ch = child(node, c, child_fresh);
      in_block(ch, level + 1, block, block_code, sub, child_fresh);
    }
    finish(node, level);
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

void bulk_update(BulkColorOcTree& tree, const RaySet& rays, const std::vector<std::uint64_t>& order,
                 const std::function<void(const octomap::OcTreeKey&, std::uint8_t[3])>& color_of) {
  if (order.empty()) return;
  bool created = false;
  Node* root = tree.ensure_root(created);
  Descent d{tree, rays.blocks(), color_of, tree.getProbHitLog(), tree.getProbMissLog(), tree.getClampingThresMinLog(),
            tree.getClampingThresMaxLog()};
  d.above_blocks(root, 0, order.data(), order.data() + order.size(), created);
}

}  // namespace scenewatch::background
