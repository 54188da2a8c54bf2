#pragma once
// What the object tracker is given of a frame: its clusters as observations (world samples and
// points, the person's touch, the level supports only) and the evidence of where objects went
// (free space in the map, what the frame sees in place).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/foreground/hand_detector.h"
#include "scenewatch/pipeline/config.h"
#include "scenewatch/pipeline/frame_result.h"
#include "scenewatch/pipeline/object_tracker.h"
#include "scenewatch/pipeline/scene_snapshot.h"

namespace scenewatch::pipeline {

/// The frame's clusters (`result.objects`) as the tracker's observations: those the foreground
/// did not claim, each with its resolution and, when the hands are this frame's, whether a hand
/// holds it; when the up is to be trusted, only those on level supports.
std::vector<TrackerObservation> tracker_input(const FrameResult& result, const Cloud& cloud, const Pose& T,
                                              const std::optional<Intrinsics>& K, const std::vector<std::size_t>& claimed,
                                              const HandsSeen& hands, std::uint64_t frame_index, const Config& config);

/// The share of `points` (world) that the map's last insertion freed or holds free.
double free_fraction(const background::OccupancyMap& map, const std::vector<Eigen::Vector3d>& points);

/// The share of `points` (world) an organized frame sees where they are: in its image, with the
/// frame's depth there within the sensor's 3 sigma plus a voxel of theirs.
double seen_in_place(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                     const std::vector<Eigen::Vector3d>& points);

/// The share of `points` (world) the frame sees where they are (as seen_in_place) on pixels the
/// hand detector gave to the person's body: a listed object found there was a piece of the person.
double seen_on_person(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                      const foreground::HandDetection& agents, const std::vector<Eigen::Vector3d>& points);

}  // namespace scenewatch::pipeline
