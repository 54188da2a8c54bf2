#pragma once
// Disjoint sets with path halving; the smaller index is the root of a union.
#include <numeric>
#include <vector>

namespace scenewatch::segmentation {

struct UnionFind {
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::vector<int> parent;
};

}  // namespace scenewatch::segmentation
