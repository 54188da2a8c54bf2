#pragma once
// One object seen in pieces: an object standing behind a narrower one shows on both sides of it
// (mOSD's occluded scenes; clutter). Two pieces are one object when the image between them is
// covered by something nearer, with no glimpse of the support or the background in between, and
// the surface continues across the gap: one straight depth profile, fitted along the line to both
// pieces' pixels next to the gap, fits both, passes behind everything in between and meets both
// pieces, and both reach the same height above the support.
#include <vector>

#include "piece.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::segmentation {

struct OcclusionParams {
  double max_height_difference_m = 0.02;  ///< the two pieces' tops (95th percentile heights)
  /// The profile fitted across the occluder meets each piece within this, plus a share of the
  /// range (depth noise grows with range).
  double max_depth_gap_m = 0.02;
  double max_depth_gap_rel = 0.03;
  /// Each piece's pixels next to the gap lie on the fitted profile within this rms. A flat face
  /// seen by a Kinect-class camera at about 1 m scatters by a few mm; two faces at different
  /// angles (two objects, not one) leave cm.
  double max_profile_rms_m = 0.008;
};

/// Joins pieces of one object seen on both sides of an occluder. Organized clouds only (the test
/// walks the image); others are returned as they are.
std::vector<Piece> join_occluded_pieces(const Cloud& cloud, std::vector<Piece> pieces, const std::vector<Plane>& planes,
                                        const OcclusionParams& params);

}  // namespace scenewatch::segmentation
