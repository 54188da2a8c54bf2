#pragma once
/// The one JSON form of an event, used wherever events are written as JSON: the model's
/// `events.jsonl`, `scenewatch diff --json`, `scenewatch replay --json` and the daemon commands'
/// `--json` (which convert the wire message back to an Event first).
///
///   {"id", "stamp_s", "level", "kind", "score", "centroid_world": [x,y,z],
///    "box_world": {"min": [x,y,z], "max": [x,y,z]}, "detail", "object_id" (or null),
///    "evidence": {name: value}, and when they apply: "region": {"x","y","width","height","area"},
///    "displacement_world": [x,y,z], "indices_before": [...], "indices_after": [...]}
#include <nlohmann/json.hpp>

#include "scenewatch/core/event.h"
#include "scenewatch/core/result.h"

namespace scenewatch {

nlohmann::json to_json(const Event& event);

/// Reads the form above; also the older model-store form (box_min/box_max, centroid,
/// displacement, region as an array) so that models saved before it still load.
Result<Event> event_from_json(const nlohmann::json& j);

EventLevel event_level_from_string(const std::string& name);  ///< throws std::invalid_argument
EventKind event_kind_from_string(const std::string& name);    ///< throws std::invalid_argument

}  // namespace scenewatch
