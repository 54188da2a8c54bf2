#pragma once
// The voxels a ray from the sensor passes through, walked as OctoMap's computeRayKeys walks them
// (Amanatides & Woo, with its float and double arithmetic, step for step), written into a RaySet.
#include <octomap/ColorOcTree.h>

#include "ray_set.h"

namespace scenewatch::background {

/// The voxels from the origin's voxel up to, not including, the end's voxel (OctoMap's ray).
void cast_ray(const octomap::ColorOcTree& tree, const octomap::point3d& origin, const octomap::OcTreeKey& key_origin,
              const octomap::point3d& end, const octomap::OcTreeKey& key_end, RaySet& rays);

/// The same voxels walked the other way, from the end's voxel centre back to the sensor, and cut
/// short where the ray has run through `stop_after` voxels in a row that other rays of this frame
/// already freed: from there on it would mostly repeat them (neighbouring rays converge towards
/// the sensor). This is voxblox's FastTsdfIntegrator shortcut (max_consecutive_ray_collisions,
/// 2 by default there); it trades a few missed voxels inside the frustum for most of the steps.
void cast_ray_back(const octomap::ColorOcTree& tree, const octomap::point3d& sensor, const octomap::OcTreeKey& key_sensor,
                   const octomap::point3d& end, const octomap::OcTreeKey& key_end, int stop_after, RaySet& rays);

}  // namespace scenewatch::background
