#pragma once
/// Checks of a frame from outside (a file, a client, a bag) before anything processes it.
#include <cstddef>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// A frame's cloud, pose, stamp, camera name and intrinsics are well formed, and the camera and
/// every valid point lie within `workspace_radius_m` of the world origin; returns the number of
/// valid points. The error names the frame's source and what is wrong.
Result<std::size_t> validate_frame(const Frame& frame, double workspace_radius_m);


}  // namespace scenewatch::io
