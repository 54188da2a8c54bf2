#pragma once
// Output of the CLI: protocol messages as JSON (nlohmann) and as human-readable text.
#include <nlohmann/json.hpp>

#include <string>

#include "scenewatch.pb.h"

namespace scenewatch::cli {

nlohmann::json to_json(const proto::Vec3& v);
nlohmann::json to_json(const proto::Box& box);
nlohmann::json to_json(const proto::OrientedBox& box);
nlohmann::json to_json(const proto::Plane& plane);
nlohmann::json to_json(const proto::Cluster& cluster);
nlohmann::json to_json(const proto::Object& object);
nlohmann::json to_json(const proto::Event& event);
nlohmann::json to_json(const proto::HealthReply& health);
nlohmann::json to_json(const proto::StatsReply& stats);
nlohmann::json to_json(const proto::IngestReply& ingest);
nlohmann::json to_json(const proto::BoxOccupancy& box);
/// Name of an occupancy state ("free", "occupied", "unknown").
std::string occupancy_name(proto::OccupancyState state);

/// "(0.123, -0.456, 0.789)"
std::string text(const proto::Vec3& v);
/// One line per plane, object or event, indented by two spaces.
std::string text(const proto::Plane& plane);
std::string text(const proto::Object& object);
std::string text(const proto::Cluster& cluster);
std::string text(const proto::Event& event);

}  // namespace scenewatch::cli
