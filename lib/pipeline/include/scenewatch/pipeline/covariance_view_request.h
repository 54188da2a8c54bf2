#pragma once
/// The seed's planner for a tracked object of the memory (NextBestView's `covariance` measures):
/// the per-point observation histories that the memory does not keep, recovered from what it
/// does keep, its appearance keyframes (posed depth images).
#include <cstdint>

#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/planning/covariance_view.h"

namespace scenewatch::pipeline {

/// The planner's request for object `object_id`: the object's points (its last observation,
/// thinned) and box_surface_samples of its box at the map's resolution, each with the centres of
/// the keyframes that observed it (planning::observing_camera_centres, depth agreement from the
/// sensor model: change.sigma_factor axial noises plus a map voxel). The sphere is centred on the
/// object's box. kNotFound for an object that is not tracked or has no points. Thread safe.
Result<planning::CovarianceViewRequest> covariance_view_request(const WorkingMemory& memory, std::uint64_t object_id,
                                                                planning::WeightRule rule, double radius_m);

}  // namespace scenewatch::pipeline
