#pragma once
// How densely the pipeline's stages sample a frame: the camera it is seen with, the pixel stride
// for work on a grid, and how far from the camera the object list looks.
#include <algorithm>
#include <cmath>
#include <optional>

#include "scenewatch/change/mismatch.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/pipeline/object_tracker.h"

namespace scenewatch::pipeline {

// The camera a frame is seen with: its intrinsics, else recovered from its organized cloud (or a
// virtual one for an unorganized cloud; change::observation_camera). Found once per frame.
inline std::optional<Intrinsics> frame_camera(const Frame& frame) {
  auto K = change::observation_camera(*frame.cloud, frame.intrinsics);
  if (!K) return std::nullopt;
  return *K;
}

// How many pixels apart an organized frame seen by camera K may be sampled for work on a grid of
// `spacing_m`: at most `most`, and only as coarse as keeps the samples within one grid cell of each
// other on a surface facing the camera at `range_m` (a VGA Kinect: 2 for the segmentation's 1 cm
// at 2 m and for the map's 2 cm at 5 m; 320x240: 1).
inline int sample_stride(const Frame& frame, const std::optional<Intrinsics>& K, double spacing_m, double range_m, int most) {
  if (most <= 1 || frame.cloud->height <= 1 || !(range_m > 0) || !K) return 1;
  return std::clamp(static_cast<int>(std::floor(spacing_m * std::min(K->fx, K->fy) / range_m)), 1, most);
}

// How far from the camera a frame sampled on every second pixel (or coarser) is segmented for the
// object list: the tracker's workspace (objects whose centroid lies farther are not objects) and
// half a metre more, for the far side of an object at its edge and for the plane it stands on.
// A room frame's far walls and floor were two thirds of its segmentation (7-Scenes kitchen: 41.6
// -> 14.6 ms in `scenewatch replay`). Frames segmented on every pixel (320x240) stay whole.
inline double workspace_range(const TrackingConfig& tracking) { return tracking.max_range_m + 0.5; }

}  // namespace scenewatch::pipeline
