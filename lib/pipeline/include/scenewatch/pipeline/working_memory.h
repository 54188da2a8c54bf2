#pragma once
/// The facade: WorkingMemory::process(frame) validates the frame, segments it, keeps the object
/// list (ObjectTracker), detects geometric changes against the background and appearance changes
/// against the keyframes, emits each change once and updates the background. It owns the modules; the service
/// talks to it and knows nothing of their insides.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include "scenewatch/background/appearance.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/change/mismatch.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/foreground/foreground_tracker.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/pipeline/event_fusion.h"
#include "scenewatch/pipeline/object_tracker.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::pipeline {

/// Everything the pipeline needs; loaded from YAML by load_config().
struct Config {
  /// The depth camera and the pose source (the `sensor:` section): every stage that weighs
  /// evidence takes it from here (WorkingMemory copies it into change.sensor).
  SensorModel sensor;
  /// Where each frame was taken: its given pose trusted, refined against the memory (default),
  /// or tracked without poses (the `localization:` section, issue 29).
  localization::Config localization;
  background::Config background;
  segmentation::Config segmentation;
  TrackingConfig tracking;
  /// Geometric change detection (OBJECT_ADDED / OBJECT_REMOVED / OBJECT_MOVED) against the map
  /// as it stood before each frame, with a persistence filter.
  bool change_enabled = true;
  change::Config change;
  background::AppearanceConfig appearance;  ///< keyframes and mesh (posed RGB-D frames only)
  surprise::SurpriseConfig surprise;        ///< image-based Bayesian surprise
  std::size_t max_event_log = 10000;  ///< events kept in memory for GetEvents
  FusionConfig fusion;                ///< one fact, one event (the `events:` section)
  foreground::ForegroundConfig foreground;  ///< hands, promotion, tracking, DoFs (issue 12)
  /// Frames whose camera or points lie farther than this from the world origin are refused, metres
  /// (the `workspace:` section's radius_m).
  double workspace_radius_m = 1000.0;
};

/// The image-based surprise of one observation against the appearance memory.
struct SurpriseResult {
  surprise::SurpriseMap map;
  std::vector<Event> events;  ///< APPEARANCE_CHANGE regions (ids set only when emitted by process())
  std::size_t reference_views = 0;
  /// The memory knows this view from an earlier visit: a keyframe within twice the keyframe
  /// spacing, taken at least `surprise.familiar_after_frames` frames before. Only then may appearance alone
  /// report a change (a view seen for the first time differs in ways that are not change:
  /// reflections, transparency, what was hidden before).
  bool familiar_view = false;
  /// Pixels of the expected view that described objects' completed surfaces set (nearer than the
  /// mesh or where it had none; WorkingMemory::set_known_surface).
  std::size_t known_surface_pixels = 0;
  Pose T_world_camera = Pose::Identity();
  Intrinsics intrinsics;
  double stamp_s = 0.0;
  double ms = 0.0;
};

Status validate(const Config& config);

/// What one frame produced.
struct FrameResult {
  std::uint64_t frame_index = 0;
  std::size_t points = 0;               ///< valid points in the frame (all of them, whatever was inserted)
  /// The pose the memory used and how it was found. A frame whose camera is lost changed nothing
  /// and raised no event.
  localization::Localization localization;
  std::vector<Plane> planes;            ///< world frame
  std::vector<ObjectCluster> objects;   ///< world frame, indices into the frame's cloud
  std::vector<Event> events;
  /// What went into the map: fewer points than the frame's while a change is pending (its points
  /// wait until it is confirmed or dropped).
  background::InsertStats insert_stats;
  std::shared_ptr<const SurpriseResult> surprise;  ///< null: the frame had no pose or no keyframes existed yet
  double segment_ms = 0, insert_ms = 0, surprise_ms = 0, change_ms = 0, total_ms = 0;
  double hands_ms = 0, foreground_ms = 0;  ///< hand detection; foreground registration and promotion
  /// Wall time of the three parts side by side (segmentation, surprise, change + insertion), and
  /// of what follows them on one core (foreground, fusion, tracker, snapshot publication).
  double parallel_ms = 0, after_ms = 0;
  std::size_t hands = 0;                   ///< hands found in the frame
  std::size_t change_candidates = 0;  ///< changes seen but not yet confirmed
};

/// An immutable view of the scene, swapped atomically after each frame: readers never wait for
/// a frame being processed.
/// A hand (with its forearm) as a planner sees it: where not to reach.
struct HandSeen {
  Aabb box_world;
  Eigen::Vector3d tip_world = Eigen::Vector3d::Zero();
  double score = 0.0;
  std::size_t pixels = 0;
  bool enters_from_border = false;
};

/// The hands and the person of the last frame that had colour.
struct HandsSeen {
  std::uint64_t frame_index = 0;
  double stamp_s = 0.0;
  std::vector<HandSeen> hands;
  std::size_t person_pixels = 0;
  std::optional<Aabb> person_box_world;
};

struct SceneSnapshot {
  std::uint64_t frames_processed = 0;
  std::vector<Plane> planes;            ///< from the last frame, world frame
  std::vector<TrackedObject> objects;   ///< background objects, then foreground ones (foreground set), world frame
  HandsSeen hands;
  /// Each object's points (world, thinned) by id: the last observation of a background object, the
  /// posed model of a foreground one. For what describes objects (the ontology's describe()).
  std::map<std::uint64_t, std::shared_ptr<const std::vector<Eigen::Vector3d>>> points;
  Eigen::Vector3d up_world = Eigen::Vector3d::UnitZ();      ///< the support's up (config or largest plane)
  Eigen::Vector3d camera_world = Eigen::Vector3d::Zero();   ///< where the last frame was taken
  double last_stamp_s = 0.0;
};

struct Stats {
  std::uint64_t frames_processed = 0;
  std::uint64_t points_processed = 0;
  std::uint64_t events_emitted = 0;
  std::size_t map_leaf_nodes = 0, map_occupied_leaves = 0, map_memory_bytes = 0;
  double map_resolution_m = 0;
  double last_frame_ms = 0, mean_frame_ms = 0;
  std::size_t tracked_objects = 0;
  std::size_t keyframes = 0, mesh_triangles = 0, appearance_memory_bytes = 0;
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

  const Config& config() const { return config_; }

 private:
  /// Loads one snapshot folder; a bad file leaves the model as it was.
  Status load_snapshot(const std::filesystem::path& dir);
  struct Impl;
  Config config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::pipeline
