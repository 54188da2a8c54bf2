#pragma once
// One fact, one event for a frame: its confirmed geometric changes, its appearance regions and
// its pending candidates through the event fusion, without what the foreground explains.
#include <cstdint>
#include <vector>

#include "map_stage.h"
#include "scenewatch/core/event.h"
#include "scenewatch/pipeline/event_fusion.h"
#include "scenewatch/pipeline/frame_result.h"

namespace scenewatch::pipeline {

/// The frame's events (without ids): appearance regions where geometry changes are their
/// evidence; others must persist (EventFusion). Changes and regions in a `quiet` box (a carried
/// object's old and new place) are left out. `known` are the tracker's objects.
std::vector<Event> frame_events(EventFusion& fusion, const FrameResult& result, const ChangeOutcome& changed,
                                const std::vector<Aabb>& quiet, double stamp_s, const std::vector<TrackedObject>& known,
                                std::uint32_t camera);

}  // namespace scenewatch::pipeline
