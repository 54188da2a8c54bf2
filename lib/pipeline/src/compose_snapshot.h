#pragma once
// The scene as readers see it after a frame (SceneSnapshot), composed from the stages' state.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "foreground_stage.h"
#include "scenewatch/pipeline/object_tracker.h"
#include "scenewatch/pipeline/scene_snapshot.h"

namespace scenewatch::pipeline {

/// Background objects then foreground ones, each with its points (world), the hands, the planes
/// and the world's up as the last frame (`T_world_camera`) saw them, and the pending changes.
std::shared_ptr<SceneSnapshot> compose_snapshot(std::uint64_t frames, const std::vector<Plane>& planes,
                                                const ObjectTracker& tracker, const ForegroundStage& foreground,
                                                const std::optional<Eigen::Vector3d>& configured_up,
                                                const Pose& T_world_camera, double last_stamp_s,
                                                std::vector<PendingChangeSeen> pending);

}  // namespace scenewatch::pipeline
