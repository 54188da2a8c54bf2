#pragma once
/// Step 1 of the hand detector (hand_detector.cpp): the grid's skin, closed and dilated so that a
/// forearm in shadow stays one piece and colour beside not-quite-registered depth still counts,
/// and the luminance that tells one skin tone from another. Private to the foreground module.
#include <cstdint>
#include <vector>

#include "frame_grid.h"

namespace scenewatch::foreground {

struct SkinCells {
  std::vector<std::uint8_t> mask;    ///< per grid cell: skin, closed and dilated
  std::vector<std::uint8_t> colour;  ///< per grid cell: skin by colour alone (before closing and dilation)
  std::vector<float> luma;           ///< per grid cell: BT.601 luminance, +1 so that ratios stay finite
  int dilation_radius = 0;           ///< grid cells the mask was dilated by
};

/// The skin of the grid, dilated by skin_dilation_px (full-resolution pixels).
SkinCells find_skin_cells(const Grid& g, int skin_dilation_px);

}  // namespace scenewatch::foreground
