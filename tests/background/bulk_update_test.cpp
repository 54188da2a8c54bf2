// The ordered bulk update against its oracle: OctoMap's own updateNode(key, hit, lazy=false),
// key by key, over rounds that clamp, prune and re-expand nodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <random>
#include <set>

#include "bulk_update.h"
#include "ray_set.h"

namespace scenewatch::background {
namespace {

using Color = std::function<void(const octomap::OcTreeKey&, std::uint8_t[3])>;

// One round of updates {Morton code -> hit}: key by key into the oracle, in Morton order, and as
// the map applies a frame (a RaySet, then one bulk update) into `bulk`.
void apply_round(BulkColorOcTree& bulk, octomap::ColorOcTree& oracle, const std::map<std::uint64_t, bool>& updates,
                 const Color& color) {
  octomap::OcTreeKey lo(0xffff, 0xffff, 0xffff), hi(0, 0, 0);
  for (const auto& [m, hit] : updates) {
    const octomap::OcTreeKey k = morton_decode(m);
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], k[i]), hi[i] = std::max(hi[i], k[i]);
  }
  RaySet rays;
  rays.reset(lo, hi);
  for (const auto& [m, hit] : updates) {
    const octomap::OcTreeKey k = morton_decode(m);
    if (hit) rays.insert_end(k);
    else rays.insert_free(k);
    oracle.updateNode(k, hit, /*lazy_eval=*/false);
    if (hit) {
      std::uint8_t rgb[3];
      color(k, rgb);
      oracle.averageNodeColor(k, rgb[0], rgb[1], rgb[2]);
    }
  }
  std::vector<std::uint64_t> order, scratch;
  rays.morton_order(order, scratch);
  bulk_update(bulk, rays, order, color);
}

TEST(BulkUpdate, MortonRoundTripAndChildOrder) {
  std::mt19937 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const octomap::OcTreeKey k(rng() & 0xffff, rng() & 0xffff, rng() & 0xffff);
    EXPECT_EQ(morton_decode(morton_encode(k)), k);
  }
  // The top three bits are OctoMap's child index at depth 0.
  const octomap::OcTreeKey k(0x8000, 0, 0x8000);
  EXPECT_EQ(morton_encode(k) >> 45, 1u + 4u);
}

TEST(BulkUpdate, RadixSortSorts) {
  std::mt19937_64 rng(2);
  std::vector<std::uint64_t> v(100000), scratch;
  for (auto& x : v) x = rng() & ((std::uint64_t{1} << 49) - 1);
  auto expected = v;
  std::sort(expected.begin(), expected.end());
  radix_sort(v, scratch, 49);
  EXPECT_EQ(v, expected);
}

// Every key of the cube [lo, hi)^3 is known in both trees or in neither, with the same log-odds;
// returns how many are known.
std::size_t expect_same_log_odds(const octomap::ColorOcTree& bulk, const octomap::ColorOcTree& oracle, unsigned lo,
                                 unsigned hi) {
  std::size_t compared = 0;
  for (unsigned x = lo; x < hi; ++x)
    for (unsigned y = lo; y < hi; ++y)
      for (unsigned z = lo; z < hi; ++z) {
        const octomap::OcTreeKey k(x, y, z);
        const auto* a = bulk.search(k);
        const auto* b = oracle.search(k);
        EXPECT_EQ(a == nullptr, b == nullptr) << x << " " << y << " " << z;
        if (a == nullptr || b == nullptr) continue;
        EXPECT_FLOAT_EQ(a->getLogOdds(), b->getLogOdds()) << x << " " << y << " " << z;
        ++compared;
      }
  return compared;
}

TEST(BulkUpdate, MatchesUpdateNodeOracle) {
  BulkColorOcTree bulk(0.05);
  octomap::ColorOcTree oracle(0.05);
  std::mt19937 rng(3);
  // Keys in a 12^3 block around the map centre, so that rounds of misses clamp whole octants
  // (which then prune) and later hits expand them again.
  auto random_key = [&] {
    return octomap::OcTreeKey(32760 + rng() % 12, 32760 + rng() % 12, 32760 + rng() % 12);
  };
  const auto color = [](const octomap::OcTreeKey& k, std::uint8_t rgb[3]) {
    rgb[0] = static_cast<std::uint8_t>(k[0]);
    rgb[1] = static_cast<std::uint8_t>(k[1]);
    rgb[2] = static_cast<std::uint8_t>(k[2]);
  };
  for (int round = 0; round < 40; ++round) {
    std::map<std::uint64_t, bool> updates;  // morton -> hit
    const double hit_share = round % 10 < 6 ? 0.0 : 0.3;  // long runs of misses, then some hits
    for (int i = 0; i < 600; ++i) {
      const octomap::OcTreeKey k = random_key();
      updates[morton_encode(k)] = std::uniform_real_distribution<>(0, 1)(rng) < hit_share;
    }
    apply_round(bulk, oracle, updates, color);
  }
  EXPECT_EQ(bulk.size(), oracle.size()) << "same nodes after pruning";
  EXPECT_EQ(bulk.getNumLeafNodes(), oracle.getNumLeafNodes());
  EXPECT_GT(expect_same_log_odds(bulk, oracle, 32756, 32776), 1000u);
}

// Whole cubes freed at once (as a room frame's rays free most 2 cm cells at 1 cm): the bulk update
// then sets the childless node itself, where OctoMap creates or expands the leaves, updates each
// and prunes them back. Cubes of 2, 4, 8 and 16 voxels (the levels inside a ray block, the block's
// own and one above it), fresh, pruned (clamped or not), with holes or with some hits, all
// against the oracle node by node.
TEST(BulkUpdate, MatchesUpdateNodeOracleWhenWholeCubesAreFreed) {
  BulkColorOcTree bulk(0.05);
  octomap::ColorOcTree oracle(0.05);
  std::mt19937 rng(5);
  const Color color = [](const octomap::OcTreeKey&, std::uint8_t rgb[3]) { rgb[0] = rgb[1] = rgb[2] = 90; };
  std::size_t whole_cube_rounds = 0;
  for (int round = 0; round < 40; ++round) {
    std::map<std::uint64_t, bool> updates;  // morton -> hit
    // An aligned cube at the map centre, whole or with holes, with or without hits.
    const unsigned size = 2u << (round % 4);
    const bool whole = round % 3 != 2, with_hits = round % 5 == 4;
    whole_cube_rounds += whole && !with_hits;
    for (unsigned x = 32768; x < 32768 + size; ++x)
      for (unsigned y = 32768; y < 32768 + size; ++y)
        for (unsigned z = 32768; z < 32768 + size; ++z) {
          if (!whole && rng() % 4 == 0) continue;
          const bool hit = with_hits && rng() % 20 == 0;
          updates[morton_encode(octomap::OcTreeKey(x, y, z))] = hit;
        }
    apply_round(bulk, oracle, updates, color);
    ASSERT_EQ(bulk.size(), oracle.size()) << "round " << round;
  }
  EXPECT_GE(whole_cube_rounds, 16u);
  EXPECT_EQ(bulk.getNumLeafNodes(), oracle.getNumLeafNodes());
  EXPECT_EQ(expect_same_log_odds(bulk, oracle, 32760, 32790), 16u * 16u * 16u);
}

// The two layouts of a ray set, a dense index over the frame's box and a hash map for boxes too
// large to index, hold the same keys and give the same Morton order.
TEST(RaySet, IndexAndHashLayoutsAgree) {
  std::mt19937 rng(7);
  RaySet indexed, hashed;
  indexed.reset(octomap::OcTreeKey(1000, 2000, 3000), octomap::OcTreeKey(1100, 2100, 3100));
  hashed.reset(octomap::OcTreeKey(0, 0, 0), octomap::OcTreeKey(0xffff, 0xffff, 0xffff));
  std::set<std::uint64_t> freed, ends;
  for (int i = 0; i < 20000; ++i) {
    const octomap::OcTreeKey k(1000 + rng() % 101, 2000 + rng() % 101, 3000 + rng() % 101);
    if (rng() % 4 == 0) {
      indexed.insert_end(k), hashed.insert_end(k);
      ends.insert(morton_encode(k));
    } else {
      indexed.insert_free(k), hashed.insert_free(k);
      freed.insert(morton_encode(k));
    }
  }
  for (std::uint64_t m : ends) freed.erase(m);
  EXPECT_EQ(indexed.count_ends(), ends.size());
  EXPECT_EQ(indexed.count_freed(), freed.size());
  EXPECT_EQ(hashed.count_ends(), ends.size());
  EXPECT_EQ(hashed.count_freed(), freed.size());
  // Every voxel of the Morton-ordered blocks, in order: the keys inserted, sorted.
  for (const RaySet* set : {&indexed, &hashed}) {
    std::vector<std::uint64_t> order, scratch, codes;
    set->morton_order(order, scratch);
    for (std::uint64_t o : order) {
      const RaySet::Block& b = set->blocks()[o & ((std::uint64_t{1} << RaySet::kNumberBits) - 1)];
      for (unsigned bit = 0; bit < RaySet::kBlockVoxels; ++bit) {
        if (((b.free[bit / 64] | b.end[bit / 64]) >> (bit % 64)) & 1) codes.push_back(((o >> RaySet::kNumberBits) << 9) | bit);
      }
    }
    std::vector<std::uint64_t> expected(freed.begin(), freed.end());
    expected.insert(expected.end(), ends.begin(), ends.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(codes, expected);
    for (std::uint64_t m : ends) EXPECT_TRUE(set->is_end(morton_decode(m)));
    for (std::uint64_t m : freed) EXPECT_TRUE(set->freed(morton_decode(m)));
  }
  EXPECT_FALSE(indexed.is_free(octomap::OcTreeKey(5000, 5000, 5000)));
  EXPECT_FALSE(hashed.is_free(octomap::OcTreeKey(5000, 5000, 5000)));
}

}  // namespace
}  // namespace scenewatch::background
