#pragma once
// The model directory on disk: snapshot folders and a `current` link swapped atomically.
//   model_dir/current -> snap-000007          (symlink, replaced by rename)
//   model_dir/snap-000007/background.ot       (OctoMap ColorOcTree)
//   model_dir/snap-000007/scene.json          (tracked objects, planes, counters)
//   model_dir/snap-000007/events.jsonl        (the event log, one JSON object per line)
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <vector>

#include "scenewatch/core/event.h"
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

/// Writes text to a file and fsyncs it.
Status write_file_synced(const std::filesystem::path& path, const std::string& text);

}  // namespace scenewatch::pipeline
