// The ordered bulk update against its oracle: OctoMap's own updateNode(key, hit, lazy=false),
// key by key, over rounds that clamp, prune and re-expand nodes.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "bulk_update.h"

namespace scenewatch::background {
namespace {

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
    std::vector<std::uint64_t> sorted;
    for (const auto& [m, hit] : updates) {
      sorted.push_back((m << 1) | (hit ? 1 : 0));
      const octomap::OcTreeKey k = morton_decode(m);
      oracle.updateNode(k, hit, /*lazy_eval=*/false);
      if (hit) {
        std::uint8_t rgb[3];
        color(k, rgb);
        oracle.averageNodeColor(k, rgb[0], rgb[1], rgb[2]);
      }
    }
    bulk_update(bulk, sorted, color);
  }
  EXPECT_EQ(bulk.size(), oracle.size()) << "same nodes after pruning";
  EXPECT_EQ(bulk.getNumLeafNodes(), oracle.getNumLeafNodes());
  EXPECT_GT(expect_same_log_odds(bulk, oracle, 32756, 32776), 1000u);
}

// Whole cubes freed at once (as a room frame's rays free most 2 cm cells at 1 cm): the bulk update
// then sets the childless node itself, where OctoMap creates or expands the leaves, updates each
// and prunes them back. Fresh cubes, pruned cubes (clamped or not) and cubes with some hits, all
// against the oracle node by node.
TEST(BulkUpdate, MatchesUpdateNodeOracleWhenWholeCubesAreFreed) {
  BulkColorOcTree bulk(0.05);
  octomap::ColorOcTree oracle(0.05);
  std::mt19937 rng(5);
  const auto color = [](const octomap::OcTreeKey&, std::uint8_t rgb[3]) { rgb[0] = rgb[1] = rgb[2] = 90; };
  std::size_t whole_cube_rounds = 0;
  for (int round = 0; round < 30; ++round) {
    std::map<std::uint64_t, bool> updates;  // morton -> hit
    // An aligned 8^3 block at the map centre, whole or with holes, with or without hits.
    const bool whole = round % 3 != 2, with_hits = round % 5 == 4;
    whole_cube_rounds += whole && !with_hits;
    for (unsigned x = 32768; x < 32776; ++x)
      for (unsigned y = 32768; y < 32776; ++y)
        for (unsigned z = 32768; z < 32776; ++z) {
          if (!whole && rng() % 4 == 0) continue;
          const bool hit = with_hits && rng() % 20 == 0;
          updates[morton_encode(octomap::OcTreeKey(x, y, z))] = hit;
        }
    std::vector<std::uint64_t> sorted;
    for (const auto& [m, hit] : updates) {
      sorted.push_back((m << 1) | (hit ? 1 : 0));
      const octomap::OcTreeKey k = morton_decode(m);
      oracle.updateNode(k, hit, /*lazy_eval=*/false);
      if (hit) oracle.averageNodeColor(k, 90, 90, 90);
    }
    bulk_update(bulk, sorted, color);
    ASSERT_EQ(bulk.size(), oracle.size()) << "round " << round;
  }
  EXPECT_GE(whole_cube_rounds, 10u);
  EXPECT_EQ(bulk.getNumLeafNodes(), oracle.getNumLeafNodes());
  EXPECT_EQ(expect_same_log_odds(bulk, oracle, 32766, 32778), 8u * 8u * 8u);
}

}  // namespace
}  // namespace scenewatch::background
