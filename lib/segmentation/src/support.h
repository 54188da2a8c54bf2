#pragma once
// What each object stands on: its plane, or another object (a box on a box).
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::segmentation {

struct SupportParams {
  /// An object whose lowest points are within this of its plane (above min_object_height_m)
  /// stands on the plane; one whose lowest points are no more than this below another object's
  /// highest ones, over that object's footprint, stands on it.
  double margin_m = 0.02;
  double min_object_height_m = 0.01;
  /// Share of the upper object's points over the lower one's footprint (or the other way round
  /// for a small box under a large one).
  double min_overlap = 0.3;
};

/// Sets ObjectCluster::supported_by for each object (indices into `objects`; -1: its plane).
void assign_supports(const Cloud& cloud, std::vector<ObjectCluster>& objects, const std::vector<Plane>& planes,
                     const SupportParams& params);

}  // namespace scenewatch::segmentation
