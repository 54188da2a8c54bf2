#pragma once
// The segmentation's part of a frame: planes and object clusters, found in the camera frame
// (indices stay those of the frame's cloud) and moved to the world. Stateless.
#include <optional>

#include "scenewatch/core/frame.h"
#include "scenewatch/pipeline/config.h"
#include "scenewatch/pipeline/frame_result.h"

namespace scenewatch::pipeline {

/// Segments `frame` (taken at `T`, seen with camera `K`) into `result.planes` and
/// `result.objects` (world frame) and sets `result.segment_ms`. Runs beside the map's and the
/// appearance's parts, which it shares nothing with.
void segment_frame(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                   FrameResult& result);

}  // namespace scenewatch::pipeline
