#pragma once
// Output of the CLI: protocol messages as JSON (nlohmann) and as human-readable text.
#include <nlohmann/json.hpp>

#include <iostream>
#include <string>

#include "scenewatch.pb.h"

namespace scenewatch::cli {

nlohmann::json to_json(const proto::Vec3& v);
/// A pose as its 16 numbers, row-major T (as the API sends it).
nlohmann::json to_json(const proto::Pose& pose);
nlohmann::json to_json(const proto::Box& box);
nlohmann::json to_json(const proto::OrientedBox& box);
nlohmann::json to_json(const proto::Plane& plane);
nlohmann::json to_json(const proto::Cluster& cluster);
nlohmann::json to_json(const proto::Object& object);
nlohmann::json to_json(const proto::Event& event);
nlohmann::json to_json(const proto::PendingChange& change);
nlohmann::json to_json(const proto::HealthReply& health);
nlohmann::json to_json(const proto::StatsReply& stats);
nlohmann::json to_json(const proto::LocalizationResult& localization);
nlohmann::json to_json(const proto::LocalizationReply& reply);
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
std::string text(const proto::PendingChange& change);
/// A camera's localization (GetLocalization), a few lines.
std::string text(const proto::LocalizationResult& localization);

/// Progress of a sequence on stderr, for terminals.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled) {}
  ~ProgressBar() { clear(); }
  void draw(std::size_t done, std::size_t total, const std::string& label) {
    if (!enabled_) return;
    constexpr std::size_t kWidth = 30;
    const std::size_t filled = total == 0 ? kWidth : done * kWidth / total;
    std::cerr << "\r\033[K[" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] " << done << "/"
              << total << " " << label << std::flush;
    shown_ = true;
  }
  void clear() {
    if (enabled_ && shown_) std::cerr << "\r\033[K" << std::flush;
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
};

}  // namespace scenewatch::cli
