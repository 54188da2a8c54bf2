#pragma once
// One frame's rays: the voxels its points end in, with their colours, and the voxels its rays pass
// through on the way there (OctoMap's discretized update: one ray per endpoint voxel, to the
// voxel's centre).
//
// A frame of many points is traced on two threads, the left and the right columns of its image,
// each into endpoints and a ray set of its own, then merged: the same split every time, so the
// same map whichever thread is faster; each half's rays still converge among themselves for the
// ray_stop_after shortcut.
#include <Eigen/Geometry>
#include <octomap/ColorOcTree.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "endpoints.h"
#include "ray_set.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/cloud.h"

namespace scenewatch::background {

struct TraceSettings {
  // The map's defaults (occupancy_map.h), which OccupancyMap::insert overrides from its Config.
  double max_range_m = Config{}.max_range_m;  ///< rays are cut here and end in a freed voxel; <= 0: no limit
  int ray_stop_after = Config{}.ray_stop_after;  ///< see cast_ray_back(); 0 casts every ray whole
  int stride = 1;            ///< every Nth pixel of every Nth row of an organized cloud
};

class FrameTrace {
 public:
  /// Traces a frame (points in the camera frame, the camera's pose in the world) into rays() and
  /// endpoints(); returns the number of valid points. A sensor outside the map's
  /// extent traces nothing.
  std::size_t trace(const octomap::ColorOcTree& tree, const Cloud& points_camera, const Eigen::Isometry3f& T_world_camera,
                    const TraceSettings& settings);
  RaySet& rays() { return halves_[0].rays; }
  const RaySet& rays() const { return halves_[0].rays; }
  /// Sorted by Morton code (Endpoints::sort_by_morton) once traced.
  Endpoints& endpoints() { return halves_[0].ends; }
  void clear();

 private:
  struct Half {
    Endpoints ends;
    std::vector<std::uint64_t> clipped;  // voxels where rays cut at max range end (pack_key)
    RaySet rays;
    std::size_t points = 0;
  };
  struct Frame;
  static void trace_columns(const Frame& frame, std::size_t first, std::size_t last, Half& half);

  Half halves_[2];
};

}  // namespace scenewatch::background
