#pragma once
// An object hypothesis before its box is made, and the joining of hypotheses found to be one.
#include <vector>

#include "union_find.h"

namespace scenewatch::segmentation {

/// Points (indices into the cloud, ascending) and the plane the piece stands on.
struct Piece {
  std::vector<int> indices;
  int plane = 0;
};

/// The pieces of each set of `sets` (over piece indices) as one piece each.
std::vector<Piece> join_pieces(const std::vector<Piece>& pieces, UnionFind& sets);

}  // namespace scenewatch::segmentation
