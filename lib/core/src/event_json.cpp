#include "scenewatch/core/event_json.h"

#include <stdexcept>

namespace scenewatch {
using nlohmann::json;

namespace {
json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
Eigen::Vector3d vec3(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }
}  // namespace

EventLevel event_level_from_string(const std::string& s) {
  for (auto l : {EventLevel::kMismatch, EventLevel::kPrediction, EventLevel::kImplausibility}) {
    if (s == to_string(l)) return l;
  }
  throw std::invalid_argument("unknown event level '" + s + "'");
}

EventKind event_kind_from_string(const std::string& s) {
  for (int k = 0; k <= static_cast<int>(EventKind::kObjectPromoted); ++k) {
    if (s == to_string(static_cast<EventKind>(k))) return static_cast<EventKind>(k);
  }
  throw std::invalid_argument("unknown event kind '" + s + "'");
}

json to_json(const Event& e) {
  json j = {{"id", e.id},
            {"stamp_s", e.stamp_s},
            {"level", to_string(e.level)},
            {"kind", to_string(e.kind)},
            {"score", e.score},
            {"centroid_world", vec(e.centroid_world)},
            {"box_world", {{"min", vec(e.box_world.min)}, {"max", vec(e.box_world.max)}}},
            {"detail", e.detail},
            {"object_id", e.object_id ? json(*e.object_id) : json(nullptr)},
            {"evidence", e.evidence.empty() ? json::object() : json(e.evidence)}};
  if (e.region) {
    j["region"] = {{"x", e.region->x}, {"y", e.region->y}, {"width", e.region->width},
                   {"height", e.region->height}, {"area", e.region->area}};
  }
  if (e.displacement_world) j["displacement_world"] = vec(*e.displacement_world);
  if (!e.indices_before.empty()) j["indices_before"] = e.indices_before;
  if (!e.indices_after.empty()) j["indices_after"] = e.indices_after;
  return j;
}

Result<Event> event_from_json(const json& j) {
  try {
    Event e;
    e.id = j.at("id").get<std::uint64_t>();
    e.stamp_s = j.at("stamp_s").get<double>();
    e.level = event_level_from_string(j.at("level").get<std::string>());
    e.kind = event_kind_from_string(j.at("kind").get<std::string>());
    e.score = j.at("score").get<double>();
    if (j.contains("box_world")) {
      e.box_world = {vec3(j.at("box_world").at("min")), vec3(j.at("box_world").at("max"))};
    } else {
      e.box_world = {vec3(j.at("box_min")), vec3(j.at("box_max"))};
    }
    e.centroid_world = vec3(j.contains("centroid_world") ? j.at("centroid_world") : j.at("centroid"));
    e.detail = j.value("detail", "");
    if (j.contains("object_id") && !j.at("object_id").is_null()) e.object_id = j.at("object_id").get<std::uint64_t>();
    if (j.contains("evidence")) e.evidence = j.at("evidence").get<std::map<std::string, double>>();
    if (j.contains("region")) {
      const auto& r = j.at("region");
      if (r.is_array()) {
        e.region = PixelRegion{r.at(0).get<int>(), r.at(1).get<int>(), r.at(2).get<int>(), r.at(3).get<int>(),
                               r.at(4).get<std::uint32_t>()};
      } else {
        e.region = PixelRegion{r.at("x").get<int>(), r.at("y").get<int>(), r.at("width").get<int>(),
                               r.at("height").get<int>(), r.at("area").get<std::uint32_t>()};
      }
    }
    if (j.contains("displacement_world")) e.displacement_world = vec3(j.at("displacement_world"));
    if (j.contains("displacement")) e.displacement_world = vec3(j.at("displacement"));
    if (j.contains("indices_before")) e.indices_before = j.at("indices_before").get<std::vector<int>>();
    if (j.contains("indices_after")) e.indices_after = j.at("indices_after").get<std::vector<int>>();
    return e;
  } catch (const std::exception& ex) {
    return invalid_argument(std::string("malformed event: ") + ex.what());
  }
}

}  // namespace scenewatch
