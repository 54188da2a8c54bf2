#pragma once
// Ordered bulk update of an OctoMap ColorOcTree.
//
// OctoMap's updateNode() walks 16 levels from the root for every key and, in lazy mode, leaves
// the inner nodes to a full-tree updateInnerOccupancy(). A frame at 1 cm touches millions of
// keys. Taken block by block in Morton order (ray_set.h), keys that share a tree path are
// neighbours, so one recursive descent visits every touched node once: children are created or
// expanded as needed, leaves get OctoMap's log-odds update, and inner occupancy, colour and
// pruning are refreshed post-order along the touched paths only. The result is the tree that
// updateNode(key, hit, lazy=false) for every key would give (same clamping, same pruning, same
// early abort on pruned nodes that are already clamped).
#include <octomap/ColorOcTree.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "ray_set.h"

namespace scenewatch::background {

/// A ColorOcTree that can create its own root, which the bulk update needs on an empty tree.
class BulkColorOcTree : public octomap::ColorOcTree {
 public:
  using octomap::ColorOcTree::ColorOcTree;
  /// The root, created when the tree is empty; `created` tells which.
  octomap::ColorOcTreeNode* ensure_root(bool& created);
};

/// Interleaves the 16-bit components of a key (x in bit 0, y in bit 1, z in bit 2, ...): at every
/// depth the three bits of one level are OctoMap's child index.
std::uint64_t morton_encode(const octomap::OcTreeKey& key);
octomap::OcTreeKey morton_decode(std::uint64_t code);

/// Sorts 64-bit values whose significant bits are below `bits` (LSD radix, 11-bit digits).
void radix_sort(std::vector<std::uint64_t>& values, std::vector<std::uint64_t>& scratch, int bits);

/// Applies a frame's rays to the tree: ends as hits, voxels passed through and not ended in as
/// misses. `order` is the rays' morton_order(); `color_of` gives the colour of a hit key.
void bulk_update(BulkColorOcTree& tree, const RaySet& rays, const std::vector<std::uint64_t>& order,
                 const std::function<void(const octomap::OcTreeKey&, std::uint8_t rgb[3])>& color_of);

}  // namespace scenewatch::background
