#pragma once
/// The facade: WorkingMemory::process(frame) validates the frame (io::validate_frame), segments it,
/// keeps the object list (ObjectTracker), detects geometric changes against the background and
/// appearance changes against the keyframes, emits each change once and updates the background.
/// It owns the stages (lib/pipeline/src: map_stage, appearance_stage, foreground_stage, ...) and
/// saves and loads through model_store; the service talks to it and knows nothing of their insides.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/colour_registration.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/surprise/surprise_map.h"
// What users of the facade's API take from it, each in a header of its own.
#include "scenewatch/pipeline/config.h"
#include "scenewatch/pipeline/frame_result.h"
#include "scenewatch/pipeline/object_class_info.h"
#include "scenewatch/pipeline/scene_snapshot.h"
#include "scenewatch/pipeline/surprise_result.h"

namespace scenewatch::ontology {
class ClassCatalog;
}  // namespace scenewatch::ontology

namespace scenewatch::pipeline {

struct Stats {
  std::uint64_t frames_processed = 0;
  std::uint64_t points_processed = 0;
  std::uint64_t events_emitted = 0;
  std::size_t map_leaf_nodes = 0, map_occupied_leaves = 0, map_memory_bytes = 0;
  double map_resolution_m = 0;
  double last_frame_ms = 0, mean_frame_ms = 0;
  std::size_t tracked_objects = 0;  ///< the object list's length (snapshot().objects): background and foreground
  std::size_t keyframes = 0, mesh_triangles = 0, appearance_memory_bytes = 0;
  /// Each camera's colour-to-depth registration as its frames measured it (sensor.fit_colour_registration), by camera name.
  std::map<std::string, ColourRegistration> colour_registration;
};

using EventCallback = std::function<void(const Event&)>;

/// Centres of the map's occupied voxels, for display.
struct OccupiedVoxels {
  std::vector<Eigen::Vector3d> centers_world;  ///< at most the asked-for count
  std::size_t total = 0;                       ///< occupied voxels in the map (finest resolution)
  std::size_t stride = 1;                      ///< every stride-th voxel was kept (1: all of them)
  double resolution_m = 0.0;
};

/// The map as OctoMap's binary stream (background::OccupancyMap::binary_data), for
/// octomap_msgs/Octomap.
struct BinaryMap {
  std::string data;
  double resolution_m = 0.0;
  std::size_t nodes = 0;       ///< inner and leaf nodes of the tree
  std::size_t leaf_nodes = 0;
};

/// Which snapshot load_newest_good() loaded, and why newer ones were refused.
struct LoadedSnapshot {
  std::filesystem::path folder;
  std::vector<std::string> refused;  ///< one message per snapshot tried before it
};

/// Thread safe: process() calls are serialised; queries may run concurrently with them.
class WorkingMemory {
 public:
  explicit WorkingMemory(Config config);
  ~WorkingMemory();

  /// Validates and processes one frame. On error nothing in the model changes.
  Result<FrameResult> process(const Frame& frame);

  std::shared_ptr<const SceneSnapshot> snapshot() const;
  Stats stats() const;
  /// Where a camera is (its last frame's localization; T_world_odom, state, quality). kNotFound,
  /// naming the known cameras, for a camera that sent no frame since the start or the last load.
  Result<localization::Localization> localization(const std::string& camera) const;
  /// Every camera that sent a frame since the start or the last load, by name ("" the default camera).
  std::vector<std::pair<std::string, localization::Localization>> localizations() const;

  background::Occupancy query(const Eigen::Vector3d& p_world) const;
  background::BoxOccupancy query_box(const Aabb& box_world) const;
  /// The occupied voxels' centres (finest resolution); when there are more than `max_count`,
  /// every k-th of them in the map's order, k the smallest stride that fits.
  OccupiedVoxels occupied_voxels(std::size_t max_count) const;
  /// The whole map as OctoMap binary data; a consistent copy while frames go on being processed.
  BinaryMap binary_map() const;
  /// A dense copy of the map in a box (background::OccupancyMap::dense_grid), for the view
  /// planner. Thread safe: a consistent copy while frames go on being processed.
  Result<background::DenseGrid> dense_grid(const Aabb& box_world, std::size_t max_voxels) const;
  /// The appearance memory's keyframes (posed colour and depth images, immutable and shared): what
  /// the memory keeps of where each surface was seen from. Thread safe.
  std::vector<std::shared_ptr<const background::Keyframe>> keyframes() const;
  std::size_t clear_box(const Aabb& box_world);
  void reset();

  /// Model directory: written to a new snapshot folder (write, fsync, rename of a `current`
  /// link), so a crash never leaves a half-written model. The newest `keep_snapshots` snapshots
  /// stay (older ones are removed): a model saved over by mistake (a Reset, then SaveModel) can
  /// be brought back by pointing `current` at the one before.
  Status save(const std::filesystem::path& model_dir, std::size_t keep_snapshots = 1) const;
  /// Loads the model that `current` points at. A missing directory is an error of kind kNotFound.
  Status load(const std::filesystem::path& model_dir);
  /// At start-up: the snapshot `current` points at or, when it does not load (damaged, missing),
  /// the newest older snapshot that does; `current` is left as it is and nothing is deleted (the
  /// next save adds a new snapshot). kNotFound when there is no saved model; an error naming every
  /// refusal when no snapshot loads.
  Result<LoadedSnapshot> load_newest_good(const std::filesystem::path& model_dir);

  /// Events are delivered on the thread that runs process(); callbacks must be quick.
  int subscribe(EventCallback callback);
  void unsubscribe(int token);
  /// Events with id > since, oldest first, at most max_count.
  std::vector<Event> events_since(std::uint64_t since, std::size_t max_count = 1000) const;
  /// The event that confirmed a pending change (snapshot().pending lists those still pending),
  /// while that event is in the log. nullopt when it is not there: the change was dropped (not
  /// seen again), was confirmed as a piece of a change told before, or its event left the log
  /// (a Reset, a load, max_event_log). Thread safe.
  std::optional<std::uint64_t> event_of_pending(std::uint64_t pending_id) const;
  /// The largest pending change id given so far (0: none); ids are never given twice. Thread safe.
  std::uint64_t last_pending_id() const;

  /// The surprise of an observation (organized, with intrinsics, colour and usually a pose)
  /// against the appearance memory. Nothing in the model changes. kNotFound before any keyframe.
  Result<std::shared_ptr<const SurpriseResult>> surprise(const Frame& observation) const;
  /// The surprise of the last processed frame that had one (null before).
  std::shared_ptr<const SurpriseResult> last_surprise() const;
  /// Writes the background's textured mesh as PLY. kNotFound before any keyframe.
  Status write_mesh(const std::filesystem::path& path) const;

  /// A surface of an object that the mesh may lack (the ontology's completed primitive of a
  /// described object, world frame): the expected view of the frames processed from now on
  /// includes it (surprise::splat_surface), so the object's unseen side is predicted when a new
  /// view shows it. Kept while the object is in the scene within 2 cm of `centroid_world` (where
  /// it was when described); a newer surface of the same object replaces it, an empty one removes
  /// it. Not saved with the model. Thread safe.
  void set_known_surface(std::uint64_t object_id, const Eigen::Vector3d& centroid_world, surprise::KnownSurface surface);

  /// The ontology's description of each object of `snapshot` (one of this memory's snapshots) by
  /// the classes of `classes`: one entry per snapshot.objects, in that order; null for an object
  /// without points. Run on request, never by process(). Cached per object: described again only
  /// when it was seen again (new points) and its description is older than 2 s. A new description
  /// makes the completed primitive the object's known surface (set_known_surface; an unknown
  /// object's is removed) and is handed to `on_described`, under the describer's lock: keep it
  /// quick. Thread safe: one object is described at a time; beside process() and the queries.
  std::vector<std::shared_ptr<const ObjectClassInfo>> describe_objects(const SceneSnapshot& snapshot,
                                                                       const ontology::ClassCatalog& classes,
                                                                       const DescribedCallback& on_described = {});

  /// describe_objects() for the one object `object_id` of `snapshot` (the same cache); null when
  /// the snapshot has no such object or it has no points.
  std::shared_ptr<const ObjectClassInfo> describe_object(const SceneSnapshot& snapshot, std::uint64_t object_id,
                                                         const ontology::ClassCatalog& classes,
                                                         const DescribedCallback& on_described = {});

  const Config& config() const { return config_; }

 private:
  /// Loads one snapshot folder; a bad file leaves the model as it was.
  Status load_snapshot(const std::filesystem::path& dir);
  struct Impl;
  Config config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::pipeline
