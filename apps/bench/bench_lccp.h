#pragma once
// PCL's supervoxels + LCCP as a segmentation baseline, kept in its own translation unit
// (bench_lccp.cpp) so the Boost.Graph-heavy PCL headers compile once.
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::bench {

/// Segments the points standing on `table` (signed distance in [cfg.min_object_height_m,
/// cfg.max_object_height_m], inside the table's hull) with pcl::SupervoxelClustering +
/// pcl::LCCPSegmentation at the parameters of PCL's LCCP example. The cloud is in its camera
/// frame (camera at the origin, z forward). Returns input indices per segment; segments with
/// fewer than cfg.min_cluster_points points are dropped.
std::vector<std::vector<int>> lccp_above_table(const Cloud& cloud, const Plane& table, const segmentation::Config& cfg);

}  // namespace scenewatch::bench
