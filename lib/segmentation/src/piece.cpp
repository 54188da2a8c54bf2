#include "piece.h"

#include <algorithm>

namespace scenewatch::segmentation {

std::vector<Piece> join_pieces(const std::vector<Piece>& pieces, UnionFind& sets) {
  std::vector<Piece> joined(pieces.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    Piece& into = joined[sets.find(static_cast<int>(p))];
    into.plane = pieces[p].plane;
    into.indices.insert(into.indices.end(), pieces[p].indices.begin(), pieces[p].indices.end());
  }
  std::vector<Piece> out;
  for (Piece& p : joined) {
    if (p.indices.empty()) continue;
    std::sort(p.indices.begin(), p.indices.end());
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace scenewatch::segmentation
