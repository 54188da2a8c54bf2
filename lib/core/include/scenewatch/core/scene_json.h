#pragma once
/// The one JSON form of planes, tracked objects and their boxes: the model's `scene.json` and the
/// live view's `/api/state` (the reading side for the model store is in the pipeline).
///
///   plane:  {"id", "normal": [x,y,z], "d", "hull": [[x,y,z], ...], "area_m2", "inlier_count", "centroid"}
///   object: {"id", "plane_id", "centroid", "box", "point_count", "mean_rgb", "rgb_covariance" (9
///            numbers, row by row), "first_seen_s", "last_seen_s", "observations", "supported_by",
///            "foreground" (foreground objects only)}
///   box:    {"center": [x,y,z], "rotation_xyzw": [x,y,z,w], "extents": [x,y,z]}
#include <nlohmann/json.hpp>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/scene.h"

namespace scenewatch {

nlohmann::json to_json(const Plane& plane);
nlohmann::json to_json(const TrackedObject& object);
nlohmann::json to_json(const OrientedBox& box);
/// {"T_world_object": 16 numbers column-major, "free": [DoF names], "handlings": [{"start_s",
/// "end_s", "range": [6], "moved": [DoF names]}], "promoted_s", "model_points", "in_hand", "visible"}
nlohmann::json to_json(const ForegroundState& state);

}  // namespace scenewatch
