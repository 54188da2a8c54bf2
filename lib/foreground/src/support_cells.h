#pragma once
/// Step 1 of the hand detector (hand_detector.cpp), its second half: the large planes of the grid
/// (table and floor, then walls), where neither a hand nor a person can be, and each cell's
/// distance to the table or floor. Private to the foreground module.
#include <vector>

#include <opencv2/core.hpp>

#include "frame_grid.h"
#include "plane_memory.h"
#include "support_plane.h"

namespace scenewatch::foreground {

struct SupportCells {
  SupportPlaneConfig plane_config;    ///< the tolerance the planes were found with
  std::vector<SupportPlane> tables;   ///< near-horizontal (table and floor), the largest first
  std::vector<float> plane_distance;  ///< per grid cell: to the nearest table or floor plane (inf: none)
  cv::Mat on_support;                 ///< g.h x g.w CV_8U: on a table, floor or wall patch
  cv::Mat near_support;               ///< on_support dilated: the band the person may not enter
};

/// The planes of the grid with the hand detector's tolerance; each memory (nullptr: none) keeps
/// its kind of plane from frame to frame (plane_memory.h).
SupportCells find_support_cells(const Grid& g, float tolerance_m, PlaneMemory* table_memory, PlaneMemory* wall_memory);

}  // namespace scenewatch::foreground
