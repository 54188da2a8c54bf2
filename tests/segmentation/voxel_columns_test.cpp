// VoxelColumns::for_each_pair against every pair of voxels, on a compact cloud (a dense column
// table) and on one spread over 20 m (too wide for the table: the hash map).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <set>
#include <utility>

#include "voxel_columns.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {
namespace {

Cloud blobs(double spread_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> centre(0.0f, static_cast<float>(spread_m)), local(-0.05f, 0.05f);
  Cloud cloud;
  for (int blob = 0; blob < 12; ++blob) {
    const float cx = centre(rng), cy = centre(rng) / 2, cz = 1.0f + centre(rng) / 4;
    for (int i = 0; i < 300; ++i) {
      PointT p;
      p.x = cx + local(rng), p.y = cy + local(rng), p.z = cz + local(rng);
      cloud.push_back(p);
    }
  }
  return cloud;
}

std::set<std::pair<int, int>> all_pairs(const VoxelIndex& grid, int reach, bool (*keep)(int)) {
  std::set<std::pair<int, int>> out;
  const int n = static_cast<int>(grid.coords.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      bool near = true;
      for (int k = 0; k < 3; ++k) near = near && std::abs(grid.coords[a][k] - grid.coords[b][k]) <= reach;
      if (near && keep(a) && keep(b)) out.insert({a, b});
    }
  return out;
}

void expect_every_pair_once(double spread_m, bool table) {
  const Cloud cloud = blobs(spread_m, 7);
  const VoxelIndex grid(cloud, 0.01);
  const VoxelColumns columns(grid);
  ASSERT_EQ(columns.uses_table(), table) << "spread " << spread_m << " m";
  bool (*keep_all)(int) = [](int) { return true; };
  bool (*keep_even)(int) = [](int v) { return v % 2 == 0; };
  for (auto keep : {keep_all, keep_even})
    for (int reach : {1, 2}) {
      std::multiset<std::pair<int, int>> found;
      columns.for_each_pair(reach, keep, [&](int a, int b) { found.insert({std::min(a, b), std::max(a, b)}); });
      const auto truth = all_pairs(grid, reach, keep);
      ASSERT_FALSE(truth.empty());
      EXPECT_EQ(found.size(), truth.size()) << "spread " << spread_m << " m, reach " << reach;
      EXPECT_TRUE(std::equal(found.begin(), found.end(), truth.begin(), truth.end())) << "spread " << spread_m << " m, reach " << reach;
    }
}

TEST(VoxelColumns, EveryPairWithinReachOnceWithTheDenseTable) { expect_every_pair_once(0.5, true); }

TEST(VoxelColumns, EveryPairWithinReachOnceWithTheHashMap) { expect_every_pair_once(20.0, false); }

}  // namespace
}  // namespace scenewatch::segmentation
