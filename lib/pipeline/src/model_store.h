#pragma once
// The model directory on disk: snapshot folders and a `current` link swapped atomically.
//   model_dir/current -> snap-000007          (symlink, replaced by rename)
//   model_dir/snap-000007/background.ot       (OctoMap ColorOcTree)
//   model_dir/snap-000007/scene.json          (tracked objects, planes, counters)
//   model_dir/snap-000007/events.jsonl        (the event log, one JSON object per line)
//   model_dir/snap-000007/keyframe-features.bin (the keyframes' features, for relocalization)
// WorkingMemory gathers what it saves under its locks and hands it here; a load reads everything
// aside first, so that a bad file leaves the model as it was.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/localization/keyframe_features.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/core/scene_json.h"  // to_json of planes and objects

namespace scenewatch::pipeline {

Result<Plane> plane_from_json(const nlohmann::json& j);
Result<TrackedObject> object_from_json(const nlohmann::json& j);

/// Writes a new snapshot folder with `write_files(dir)`, fsyncs it, then points `current` at it
/// and removes the snapshots older than the newest `keep` (at least the new one stays).
Status commit_snapshot(const std::filesystem::path& model_dir,
                       const std::function<Status(const std::filesystem::path&)>& write_files, std::size_t keep = 1);

/// The folder `current` points at; kNotFound when there is no saved model.
Result<std::filesystem::path> current_snapshot(const std::filesystem::path& model_dir);

/// The snapshot folders of a model directory (snap-NNNNNN), newest first.
std::vector<std::filesystem::path> snapshots_newest_first(const std::filesystem::path& model_dir);

/// What scene.json records of the background map file, checked when it is loaded (OctoMap reads
/// a truncated .ot without complaint).
struct BackgroundRecord {
  std::uint64_t bytes = 0;
  std::size_t leaf_nodes = 0;
};

/// A snapshot's contents besides the background map and the keyframes: scene.json, events.jsonl
/// and the keyframes' features.
struct SceneRecord {
  std::uint64_t frames = 0, points = 0, next_object_id = 1, next_event_id = 1;
  double last_stamp_s = 0.0;
  BackgroundRecord background;
  std::vector<TrackedObject> objects;                             ///< background objects
  std::map<std::uint64_t, std::vector<Eigen::Vector3d>> samples;  ///< their free-space samples, by id
  /// Foreground objects with their point models (object frame), so that a restarted daemon tracks
  /// them and keeps their learnt DoFs.
  std::vector<std::pair<TrackedObject, CloudConstPtr>> foreground;
  std::vector<Plane> planes;
  std::deque<Event> events;
  std::vector<localization::SavedFeatures> features;  ///< empty in models saved before them
};

/// Writes `map` as background.ot in the snapshot folder `dir`; returns what scene.json records of it.
Result<BackgroundRecord> save_background(const background::OccupancyMap& map, const std::filesystem::path& dir);
/// Writes the keyframes' features, scene.json and events.jsonl into the snapshot folder `dir`.
Status write_scene(const std::filesystem::path& dir, const SceneRecord& scene);
/// Reads the snapshot folder `dir`: its background into `map` (checked against its record), the
/// rest as returned. An error names the file and what is wrong with it.
Result<SceneRecord> read_snapshot(const std::filesystem::path& dir, background::OccupancyMap& map);

/// At start-up: `load`s the snapshot `current` points at or, when that fails, the newest older
/// snapshot that loads; returns the folder loaded and one message per snapshot refused before it.
/// kNotFound when there is no saved model; an error naming every refusal when no snapshot loads.
Result<std::pair<std::filesystem::path, std::vector<std::string>>> load_newest_good(
    const std::filesystem::path& model_dir, const std::function<Status(const std::filesystem::path&)>& load);

/// Writes text to a file and fsyncs it.
Status write_file_synced(const std::filesystem::path& path, const std::string& text);

}  // namespace scenewatch::pipeline
