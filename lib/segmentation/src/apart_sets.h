#pragma once
// Joining sets strongest evidence first while some pairs must stay apart, not even joined through
// a third set (a row of patches straddling a crease, a fragment touching two objects).
#include <map>
#include <set>

#include "union_find.h"

namespace scenewatch::segmentation {

/// Per set root: the roots of the sets it must stay apart from.
using ApartSets = std::map<int, std::set<int>>;

/// Joins the sets of a and b unless one must stay apart from the other; the joined set keeps
/// both sets' apart lists. Returns whether they are one set now.
inline bool unite_unless_apart(UnionFind& sets, ApartSets& apart, int a, int b) {
  const int ra = sets.find(a), rb = sets.find(b);
  if (ra == rb) return true;
  for (int x : apart[ra])
    if (sets.find(x) == rb) return false;
  sets.unite(ra, rb);
  const int root = sets.find(ra), other = root == ra ? rb : ra;
  apart[root].insert(apart[other].begin(), apart[other].end());
  return true;
}

}  // namespace scenewatch::segmentation
