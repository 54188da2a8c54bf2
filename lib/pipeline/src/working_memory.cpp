// The working memory: the facade that runs each frame through its stages (localization, the
// foreground, then the map, the appearance and the segmentation side by side, then the object
// list and the event fusion) and publishes the result: events out, an immutable snapshot for
// readers. Each stage lives in a file of its own; saving and loading are model_store's.
#include "scenewatch/pipeline/working_memory.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <future>
#include <optional>

#include "appearance_stage.h"
#include "camera_registry.h"
#include "colour_registration_stage.h"
#include "compose_snapshot.h"
#include "event_log.h"
#include "foreground_stage.h"
#include "frame_events.h"
#include "frame_sampling.h"
#include "known_surfaces.h"
#include "map_stage.h"
#include "model_store.h"
#include "object_describer.h"
#include "object_observations.h"
#include "segmentation_stage.h"
#include "timing.h"
#include "scenewatch/io/frame_validation.h"

namespace scenewatch::pipeline {
namespace fs = std::filesystem;

namespace {

// The frame at the pose localization found (unchanged when its pose was taken as given).
Frame placed(const Frame& frame, const localization::Localization& where) {
  if (where.state == localization::State::kGiven) return frame;
  Frame out = frame;
  out.T_world_camera = where.T_world_camera;
  return out;
}

// The one sensor model, handed to every stage that weighs evidence.
Config with_sensor(Config c) {
  c.change.sensor = c.sensor;
  c.segmentation.sensor = c.sensor;
  return c;
}

}  // namespace

struct WorkingMemory::Impl {
  explicit Impl(const Config& c)
      : map(c, pending_ids), appearance(c.appearance, c.surprise), localizer(c.localization, c.sensor), colour(c.sensor),
        tracker(c.tracking), fusion(c.fusion, pending_ids), foreground(c.foreground), snapshot(std::make_shared<SceneSnapshot>()),
        up(c.segmentation.up) {}

  // The ids of pending changes, geometric and appearance alike (one id names one change); never
  // reset, so an id is not given twice while the memory lives. Declared first: the stages share it.
  const std::shared_ptr<change::PendingIds> pending_ids = std::make_shared<change::PendingIds>();

  // process() and the other writers hold this for their whole duration.
  mutable std::mutex writer;
  MapStage map;                       // the background map and the change detection; locks itself for readers
  AppearanceStage appearance;         // keyframes, mesh and image surprise; locks itself for readers
  localization::Localizer localizer;  // where each camera is, against the keyframes (writer only)
  ColourRegistrationStage colour;     // each camera's colour laid onto its depth (writer only)

  // Owned by the writer.
  ObjectTracker tracker;
  EventFusion fusion;
  ForegroundStage foreground;
  CameraRegistry cameras;
  std::vector<Plane> planes;  // the last frame's
  std::map<std::uint32_t, std::vector<Plane>> planes_by_camera;  // each camera's last frame's
  Pose last_camera = Pose::Identity();
  std::uint64_t frames = 0, points = 0;
  double total_ms = 0, last_ms = 0;
  double last_stamp_s = 0.0;

  std::shared_ptr<const SceneSnapshot> snapshot;  // read and written with std::atomic_load/store
  KnownSurfaces known;                            // of described objects (set_known_surface)
  ObjectDescriber describer{known};               // the ontology, on request; locks itself
  EventLog events;
  std::optional<Eigen::Vector3d> up;  // the configured up direction (segmentation.up_vector)

  void publish() {
    auto s = compose_snapshot(frames, planes, tracker, foreground, up, last_camera, last_stamp_s, pending_seen());
    std::atomic_store(&snapshot, std::shared_ptr<const SceneSnapshot>(std::move(s)));
  }

  // The unconfirmed changes, geometric then appearance-only, each with its camera's name.
  std::vector<PendingChangeSeen> pending_seen() const {
    std::vector<PendingChangeSeen> out;
    for (const auto& c : map.pending()) out.push_back({c, cameras.name_of(c.camera)});
    for (const auto& c : fusion.pending()) out.push_back({c, cameras.name_of(c.camera)});
    return out;
  }

  // The object list (no events: a change is reported by the change detector, once); the
  // foreground's objects are not background objects.
  void track_objects(const FrameResult& result, const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K,
                     const std::vector<std::size_t>& claimed, const Config& config) {
    std::vector<TrackerObservation> observations =
        tracker_input(result, *frame.cloud, T, K, claimed, foreground.hands(), frames, config);
    map.read([&](const background::OccupancyMap& bg) {
      tracker.update(std::move(observations), frame.stamp_s,
                     [&](const std::vector<Eigen::Vector3d>& pts) { return free_fraction(bg, pts); },
                     [&](const std::vector<Eigen::Vector3d>& pts) { return seen_in_place(*frame.cloud, T, K, config, pts); },
                     [&](const std::vector<Eigen::Vector3d>& pts) {
                       return seen_on_person(*frame.cloud, T, K, config, foreground.agents(), pts);
                     });
    });
  }

  // The id of the frame's camera; a camera forgotten to make room takes its per-camera state along.
  std::uint32_t camera_of(const Frame& frame) {
    std::optional<std::uint32_t> forgotten;
    const std::uint32_t id = cameras.id(frame.camera, &forgotten);
    if (forgotten) {
      map.forget_camera(*forgotten);
      fusion.forget_camera(*forgotten);
      foreground.forget_camera(*forgotten);
      appearance.forget_camera(*forgotten);
      localizer.forget_camera(*forgotten);
      colour.forget_camera(*forgotten);
      planes_by_camera.erase(*forgotten);
    }
    return id;
  }
};

namespace {

// Hands the map's thread its job once: give() does, or, on any other way out of process(), the
// destructor hands it none, so that the thread ends and its future can be waited for.
class JobHandover {
 public:
  explicit JobHandover(std::promise<std::function<ChangeOutcome()>>& job) : job_(job) {}
  JobHandover(const JobHandover&) = delete;
  JobHandover& operator=(const JobHandover&) = delete;
  ~JobHandover() {
    if (!given_) job_.set_value({});
  }
  void give(std::function<ChangeOutcome()> run) {
    given_ = true;
    job_.set_value(std::move(run));
  }

 private:
  std::promise<std::function<ChangeOutcome()>>& job_;
  bool given_ = false;
};

}  // namespace

WorkingMemory::WorkingMemory(Config config) : config_(with_sensor(std::move(config))), impl_(std::make_unique<Impl>(config_)) {}
WorkingMemory::~WorkingMemory() = default;

Result<FrameResult> WorkingMemory::process(const Frame& original) {
  const auto valid_points = io::validate_frame(original, config_.workspace_radius_m);
  if (!valid_points) return valid_points.error();
  const auto t0 = Clock::now();
  std::lock_guard<std::mutex> lock(impl_->writer);
  Impl& m = *impl_;
  FrameResult result;
  result.frame_index = m.frames;
  result.points = *valid_points;
  const std::uint32_t camera_id = m.camera_of(original);
  // The map's part of the frame runs on a second thread, started here. It first fills the change
  // detection's copy of the map at the frame's given pose, beside the colour registration, the
  // localization and the hand detection on this thread (kitchen: a 6.4 ms fill against about 5
  // ms of those); then it waits for the job below. One thread for both: a thread started for the
  // job while the fill still ran made three share two cores, and the job's start waited up to
  // 3.5 ms for one (cup_added). A pose the localization moves so far that the copy no longer
  // holds the frame's box has it filled again.
  const bool detect = config_.change_enabled && m.frames > 0;
  const bool fill_ahead = detect && original.T_world_camera && frame_camera(original);
  std::promise<std::function<ChangeOutcome()>> map_job;
  auto map_part = std::async(std::launch::async, [&, job = map_job.get_future()]() mutable {
    if (fill_ahead) m.map.prefill(original, *original.T_world_camera, config_.change);
    const auto run = job.get();
    return run ? run() : ChangeOutcome{};
  });
  // Every way out of this function hands the thread a job (none on the way out early).
  JobHandover handover(map_job);
  const Frame registered = m.colour.registered(original, camera_id);
  // Where the frame was taken, against the memory; a camera that is lost changes nothing.
  result.localization = m.localizer.localize(
      registered, camera_id, [&](const Pose& p, std::size_t n) { return m.appearance.nearest(p, n); },
      [&] { return m.appearance.all_keyframes(); });
  if (!result.localization.placed()) {
    handover.give({});
    map_part.get();
    m.map.drop_prefill();
    ++m.frames;
    result.total_ms = ms_since(t0);
    return result;
  }
  const Frame frame = placed(registered, result.localization);
  const Pose T = frame.pose_or_identity();
  // Hands, the person and the foreground objects are blanked out of what the background sees.
  // The planes this camera saw last (world frame); a camera's first frame starts from the model's.
  const auto own_planes = m.planes_by_camera.find(camera_id);
  const Frame seen = m.foreground.prepare(frame, m.frames, own_planes != m.planes_by_camera.end() ? own_planes->second : m.planes,
                                          config_.segmentation.up, m.map.occupied_fraction(config_.change, camera_id), result, camera_id);

  // Three independent parts, each against the memory as it stands before this frame: the
  // geometric change detection with the map update (the octree), the image surprise (keyframes
  // and mesh) and the segmentation of the frame. None reads what another writes; the tracker and
  // the event fusion below need all three. Two threads for two cores: the map's part (the
  // insertion must wait for the change detection) on one, the segmentation on this one, and the
  // image surprise on whichever is free first. Three threads made the three share two cores, and
  // the map's part, which the frame waited for, ran at two thirds of a core (kitchen 76.6 -> 57.0
  // ms per frame). The map's part is the longest in a room (kitchen: 34 against 14 and 14 ms);
  // with a person or a table across the view the segmentation is (hrt1: 32 against 22 for the
  // map), and the surprise fixed on this thread made the frame wait for both.
  const auto known_surfaces = m.known.current(*std::atomic_load(&m.snapshot));
  const std::optional<Intrinsics> camera = frame_camera(seen);
  std::atomic<bool> surprise_taken{false};
  const auto image_surprise = [&] {
    if (surprise_taken.exchange(true)) return;
    const auto t_surprise = Clock::now();
    result.surprise = m.appearance.process(seen, known_surfaces, camera_id);  // then its keyframe update
    result.surprise_ms = ms_since(t_surprise);
  };
  const auto t_parallel = Clock::now();
  handover.give([&] {
    // A frame with a person blanked out of it has holes that are no sensor's (nor is black hair
    // beside the blanked face): its holes are not recorded as space the sensor got nothing from.
    const bool own_holes = seen.cloud == frame.cloud;
    ChangeOutcome out = m.map.update(seen, T, camera, config_, detect, result, camera_id, own_holes);
    image_surprise();
    m.map.witness_frame();
    return out;
  });
  segment_frame(seen, T, camera, config_, result);  // in the camera frame, then moved to the world
  image_surprise();
  m.map.witness_frame();  // taken here when the map's thread is still inserting

  const ChangeOutcome changed = map_part.get();
  result.parallel_ms = ms_since(t_parallel);
  const auto t_after = Clock::now();
  foreground::ForegroundUpdate fg = m.foreground.update(result.objects, m.tracker.objects(), result);
  result.events = frame_events(m.fusion, result, changed, fg.quiet_boxes, frame.stamp_s, m.tracker.objects(), camera_id);

  m.track_objects(result, frame, T, camera, fg.claimed_clusters, config_);
  for (std::uint64_t id : fg.promoted) m.tracker.remove(id);
  if (!fg.vacated.empty()) {
    // A promoted object's old place is empty now: its removal is explained, not a surprise.
    m.map.write([&](background::OccupancyMap& bg) {
      for (const auto& pts : fg.vacated) bg.set_voxels(pts, background::Occupancy::kFree);
    });
  }
  for (auto& e : fg.events) result.events.push_back(std::move(e));

  m.planes = result.planes;
  for (auto& p : m.planes) p.indices.clear();
  m.planes_by_camera[camera_id] = m.planes;
  m.last_camera = T;
  ++m.frames;
  m.last_stamp_s = frame.stamp_s;
  m.points += result.points;
  result.total_ms = ms_since(t0);
  m.last_ms = result.total_ms;
  m.total_ms += result.total_ms;
  m.events.emit(result.events, config_.max_event_log);
  m.publish();
  result.after_ms = ms_since(t_after);
  return result;
}

std::shared_ptr<const SceneSnapshot> WorkingMemory::snapshot() const { return std::atomic_load(&impl_->snapshot); }

Stats WorkingMemory::stats() const {
  Stats s;
  {
    std::lock_guard<std::mutex> lock(impl_->writer);
    s.frames_processed = impl_->frames;
    s.points_processed = impl_->points;
    s.last_frame_ms = impl_->last_ms;
    s.mean_frame_ms = impl_->frames ? impl_->total_ms / impl_->frames : 0.0;
    s.tracked_objects = impl_->tracker.objects().size() + impl_->foreground.tracker().objects().size();
    s.keyframes = impl_->appearance.keyframes();
    s.mesh_triangles = impl_->appearance.triangles();
    s.appearance_memory_bytes = impl_->appearance.memory_bytes();
    const auto measured = impl_->colour.measured();
    for (const auto& [name, id] : impl_->cameras.names())
      if (auto it = measured.find(id); it != measured.end()) s.colour_registration[name] = it->second;
    impl_->map.read([&](const background::OccupancyMap& map) {
      s.map_leaf_nodes = map.num_leaf_nodes();
      s.map_occupied_leaves = map.num_occupied_leaves();
      s.map_memory_bytes = map.memory_bytes();
      s.map_resolution_m = map.resolution();
    });
  }
  s.events_emitted = impl_->events.emitted();
  return s;
}

background::Occupancy WorkingMemory::query(const Eigen::Vector3d& p) const {
  return impl_->map.read([&](const background::OccupancyMap& map) { return map.query(p); });
}

OccupiedVoxels WorkingMemory::occupied_voxels(std::size_t max_count) const {
  OccupiedVoxels out;
  impl_->map.read([&](const background::OccupancyMap& map) {
    out.centers_world = map.occupied_voxel_centers();
    out.resolution_m = map.resolution();
  });
  out.total = out.centers_world.size();
  if (max_count == 0) {
    out.centers_world.clear();
    out.stride = out.total == 0 ? 1 : out.total;
    return out;
  }
  out.stride = (out.total + max_count - 1) / max_count;
  if (out.stride > 1) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < out.total; i += out.stride) out.centers_world[kept++] = out.centers_world[i];
    out.centers_world.resize(kept);
  }
  out.stride = std::max<std::size_t>(out.stride, 1);
  return out;
}

BinaryMap WorkingMemory::binary_map() const {
  BinaryMap out;
  impl_->map.read([&](const background::OccupancyMap& map) {
    out.data = map.binary_data();
    out.resolution_m = map.resolution();
    out.nodes = map.num_nodes();
    out.leaf_nodes = map.num_leaf_nodes();
  });
  return out;
}

background::BoxOccupancy WorkingMemory::query_box(const Aabb& box) const {
  return impl_->map.read([&](const background::OccupancyMap& map) { return map.query_box(box); });
}

Result<background::DenseGrid> WorkingMemory::dense_grid(const Aabb& box, std::size_t max_voxels) const {
  return impl_->map.read([&](const background::OccupancyMap& map) { return map.dense_grid(box, max_voxels); });
}

std::vector<std::shared_ptr<const background::Keyframe>> WorkingMemory::keyframes() const {
  return impl_->appearance.all_keyframes();
}

std::size_t WorkingMemory::clear_box(const Aabb& box) {
  std::lock_guard<std::mutex> lock(impl_->writer);
  return impl_->map.write([&](background::OccupancyMap& map) { return map.clear_box(box); });
}

void WorkingMemory::reset() {
  std::lock_guard<std::mutex> lock(impl_->writer);
  Impl& m = *impl_;
  m.map.reset();
  m.appearance.reset();
  m.localizer.reset();
  m.known.clear();
  m.describer.clear();  // its cache made those surfaces: a reused id is described anew
  m.tracker.reset();
  m.fusion.reset();
  m.foreground.reset();
  m.planes.clear();
  m.planes_by_camera.clear();
  m.colour.reset();
  m.cameras.reset();
  m.last_camera = Pose::Identity();
  m.frames = m.points = 0;
  m.total_ms = m.last_ms = 0;
  m.last_stamp_s = 0.0;
  m.events.clear();  // Reset forgets everything; ids keep counting, so none is given twice
  m.publish();
}

Result<localization::Localization> WorkingMemory::localization(const std::string& camera) const {
  std::lock_guard<std::mutex> lock(impl_->writer);
  const auto id = impl_->cameras.find(camera);
  const auto last = id ? impl_->localizer.last(*id) : std::nullopt;
  if (last) return *last;
  std::string known;
  for (const auto& [name, cam] : impl_->cameras.names()) known += (known.empty() ? "" : ", ") + ("'" + name + "'");
  return not_found("camera '" + camera + "': no frame from it since the start or the last load (known: " +
                   (known.empty() ? std::string("none") : known) + ")");
}

std::vector<std::pair<std::string, localization::Localization>> WorkingMemory::localizations() const {
  std::lock_guard<std::mutex> lock(impl_->writer);
  std::vector<std::pair<std::string, localization::Localization>> out;
  for (const auto& [name, id] : impl_->cameras.names())
    if (auto last = impl_->localizer.last(id)) out.emplace_back(name, *last);
  return out;
}

Status WorkingMemory::save(const fs::path& model_dir, std::size_t keep_snapshots) const {
  std::lock_guard<std::mutex> lock(impl_->writer);
  const Impl& m = *impl_;
  return commit_snapshot(model_dir, [&](const fs::path& dir) -> Status {
    auto background = m.map.read([&](const background::OccupancyMap& map) { return save_background(map, dir); });
    if (!background) return background.error();
    SceneRecord scene;
    scene.background = *background;
    scene.frames = m.frames;
    scene.points = m.points;
    scene.next_object_id = m.tracker.next_id();
    scene.last_stamp_s = m.last_stamp_s;
    scene.objects = m.tracker.objects();
    for (const auto& o : scene.objects)
      if (const auto* samples = m.tracker.samples(o.id)) scene.samples[o.id] = *samples;
    for (const auto& o : m.foreground.tracker().objects()) scene.foreground.emplace_back(o, m.foreground.tracker().model(o.id));
    scene.planes = m.planes;
    std::tie(scene.events, scene.next_event_id) = m.events.contents();
    if (auto st = m.appearance.save(dir); !st) return st;
    // The keyframes' features, for relocalization (homing) after a restart.
    scene.features = m.localizer.relocalizer().to_save(m.appearance.all_keyframes());
    return write_scene(dir, scene);
  }, keep_snapshots);
}

Status WorkingMemory::load(const fs::path& model_dir) {
  auto dir = current_snapshot(model_dir);
  if (!dir) return dir.error();
  return load_snapshot(*dir);
}

Result<LoadedSnapshot> WorkingMemory::load_newest_good(const fs::path& model_dir) {
  auto loaded = pipeline::load_newest_good(model_dir, [this](const fs::path& dir) { return load_snapshot(dir); });
  if (!loaded) return loaded.error();
  return LoadedSnapshot{loaded->first, loaded->second};
}

Status WorkingMemory::load_snapshot(const fs::path& dir) {
  // Everything is read aside first: a bad file leaves the model as it was.
  background::OccupancyMap map(config_.background);
  auto scene = read_snapshot(dir, map);
  if (!scene) return scene.error();

  std::lock_guard<std::mutex> lock(impl_->writer);
  Impl& m = *impl_;
  // Keyframes last among the reads: AppearanceStage::load changes nothing when it fails.
  if (auto st = m.appearance.load(dir); !st) return st;
  // Every camera homes anew: its frames are relocalized against the loaded keyframes.
  m.localizer.reset();
  m.localizer.relocalizer().restore(scene->features, m.appearance.all_keyframes());
  m.map.replace(std::move(map));  // and no candidates
  config_.background.resolution_m = m.map.read([](const background::OccupancyMap& bg) { return bg.resolution(); });
  m.tracker.restore(std::move(scene->objects), std::move(scene->samples), scene->next_object_id);
  m.foreground.reset();
  for (const auto& [object, model] : scene->foreground) m.foreground.tracker().restore(object, model);
  m.fusion.reset();
  m.planes = std::move(scene->planes);
  m.planes_by_camera.clear();
  m.colour.reset();
  m.cameras.reset();
  m.frames = scene->frames;
  m.points = scene->points;
  m.last_stamp_s = scene->last_stamp_s;
  m.events.restore(std::move(scene->events), scene->next_event_id);
  m.publish();
  return {};
}

int WorkingMemory::subscribe(EventCallback callback) { return impl_->events.subscribe(std::move(callback)); }

void WorkingMemory::unsubscribe(int token) { impl_->events.unsubscribe(token); }

std::vector<Event> WorkingMemory::events_since(std::uint64_t since, std::size_t max_count) const {
  return impl_->events.since(since, max_count);
}

std::optional<std::uint64_t> WorkingMemory::event_of_pending(std::uint64_t pending_id) const {
  return impl_->events.confirmed_by(pending_id);
}

std::uint64_t WorkingMemory::last_pending_id() const { return impl_->pending_ids->last(); }

Result<std::shared_ptr<const SurpriseResult>> WorkingMemory::surprise(const Frame& observation) const {
  if (auto valid = io::validate_frame(observation, config_.workspace_radius_m); !valid) return valid.error();
  return impl_->appearance.evaluate(observation);
}

std::shared_ptr<const SurpriseResult> WorkingMemory::last_surprise() const { return impl_->appearance.last(); }

Status WorkingMemory::write_mesh(const fs::path& path) const { return impl_->appearance.write_mesh(path); }

void WorkingMemory::set_known_surface(std::uint64_t object_id, const Eigen::Vector3d& centroid_world, surprise::KnownSurface surface) {
  impl_->known.set(object_id, centroid_world, std::move(surface));
}

std::vector<std::shared_ptr<const ObjectClassInfo>> WorkingMemory::describe_objects(const SceneSnapshot& snapshot,
                                                                                    const ontology::ClassCatalog& classes,
                                                                                    const DescribedCallback& on_described) {
  return impl_->describer.describe(snapshot, classes, on_described);
}

std::shared_ptr<const ObjectClassInfo> WorkingMemory::describe_object(const SceneSnapshot& snapshot, std::uint64_t object_id,
                                                                      const ontology::ClassCatalog& classes,
                                                                      const DescribedCallback& on_described) {
  return impl_->describer.describe_one(snapshot, object_id, classes, on_described);
}

}  // namespace scenewatch::pipeline
