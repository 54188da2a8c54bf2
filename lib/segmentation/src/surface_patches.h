#pragma once
// The surface patches of one cluster for the convexity test (convex_parts.h): the cells of a voxel
// grid over its points. On an organized cloud a cell that straddles a depth step (depth_steps.h),
// the edge of a book lying on a book, is cut there into the pieces of each side, and two patches
// whose pixels meet mostly across steps are marked as a step: one surface in front of another,
// whatever their normals say. Unorganized clouds keep the plain cells.
// The image is what tells surfaces that touch from surfaces that only come close in space.
#include <Eigen/Core>

#include <optional>
#include <utility>
#include <vector>

#include "depth_steps.h"
#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

struct SurfacePatches {
  std::vector<std::vector<int>> members;      ///< per patch its points (indices into the cloud)
  std::vector<std::pair<int, int>> adjacent;  ///< neighbouring patches (26-neighbourhood of their cells), each pair once
  /// Per adjacent pair: their pixels meet in the image (always true for unorganized clouds).
  /// Cells next to each other in space whose pixels do not meet may be one surface in front of
  /// another (the edge of a book lying on a round tin).
  std::vector<char> touching;
  std::vector<char> stepped;  ///< per adjacent pair: their pixels meet mostly across depth steps
};

/// Patches of `cluster` at cell edge `patch_size_m`; cut at depth steps when `steps` is given and
/// the cloud is organized.
SurfacePatches surface_patches(const Cloud& cloud, const std::vector<int>& cluster, double patch_size_m,
                               const Eigen::Vector3d& sensor_origin, const std::optional<DepthStepParams>& steps);

}  // namespace scenewatch::segmentation
