#pragma once
// One object seen in pieces: an object standing behind a narrower one shows on both sides of it
// (mOSD's occluded scenes; clutter). Two pieces are one object when the image between them is
// covered by something nearer, with no glimpse of the support or the background in between, and
// the surface continues across the gap: the depth of one piece, carried on along the line to the
// other, meets the other's depth, and both reach the same height above the support.
#include <vector>

#include "piece.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::segmentation {

struct OcclusionParams {
  double max_height_difference_m = 0.02;  ///< the two pieces' tops (95th percentile heights)
  /// The surface carried across the occluder meets the other piece within this, plus a share
  /// of the range (depth noise grows with range).
  double max_depth_gap_m = 0.02;
  double max_depth_gap_rel = 0.03;
};

/// Joins pieces of one object seen on both sides of an occluder. Organized clouds only (the test
/// walks the image); others are returned as they are.
std::vector<Piece> join_occluded_pieces(const Cloud& cloud, std::vector<Piece> pieces, const std::vector<Plane>& planes,
                                        const OcclusionParams& params);

}  // namespace scenewatch::segmentation
