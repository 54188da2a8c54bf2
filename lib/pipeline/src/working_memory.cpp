// The working memory: one frame at a time through validate -> segment -> track -> update the
// background, with events out and an immutable snapshot for readers.
#include "scenewatch/pipeline/working_memory.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <future>
#include <limits>
#include <optional>
#include <sstream>

#include "appearance_stage.h"
#include "camera_registry.h"
#include "foreground_stage.h"
#include "model_store.h"
#include "timing.h"
#include "scenewatch/change/objects.h"
#include "scenewatch/change/persistence.h"
#include "scenewatch/core/event_json.h"

namespace scenewatch::pipeline {
namespace fs = std::filesystem;

namespace {

// Farther than any depth sensor sees (lidars reach a few hundred metres).
constexpr float kMaxPointRangeM = 1000.0f;
// A camera's name is a label (a serial number, a topic, "head"), not a text.
constexpr std::size_t kMaxCameraName = 128;

Status validate_camera_name(const std::string& name, const std::string& where) {
  if (name.size() > kMaxCameraName) {
    return invalid_argument(where + ": camera name is " + std::to_string(name.size()) + " bytes long, at most " +
                            std::to_string(kMaxCameraName) + " are allowed");
  }
  for (unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) return invalid_argument(where + ": camera name contains a control character");
  }
  return {};
}

std::string metres(double m) {
  std::ostringstream os;
  os << m << " m";
  return os.str();
}

// Checks a frame; returns its number of valid points (one pass over the cloud serves both). The
// camera and every point must lie within `workspace_radius_m` of the world origin: a pose at 1e30
// is finite and rigid, and would put objects, keyframes and a mesh there (OctoMap alone drops
// such points without a word).
Result<std::size_t> validate_frame(const Frame& f, double workspace_radius_m) {
  const std::string where = f.source.empty() ? std::string("frame") : "frame from '" + f.source + "'";
  const std::string workspace = "outside the workspace (workspace.radius_m: " + metres(workspace_radius_m) +
                                " around the world origin)";
  if (!f.cloud || f.cloud->empty()) return invalid_argument(where + ": cloud is empty");
  if (f.cloud->width * f.cloud->height != f.cloud->size()) {
    return invalid_argument(where + ": cloud width x height (" + std::to_string(f.cloud->width) + "x" +
                            std::to_string(f.cloud->height) + ") does not match its " + std::to_string(f.cloud->size()) + " points");
  }
  if (f.T_world_camera) {
    if (auto st = validate_rigid(f.T_world_camera->matrix()); !st) return invalid_argument(where + ": " + st.error().message);
    const double camera_m = f.T_world_camera->translation().norm();
    if (camera_m > workspace_radius_m) {
      return invalid_argument(where + ": the camera pose lies " + metres(camera_m) + " from the world origin, " + workspace);
    }
  }
  // Finite is not enough: a point at 3e38 m would be ray-cast through the map. No depth sensor
  // sees that far; such coordinates are not metres (wrong units, garbage).
  const Pose T = f.pose_or_identity();
  const double workspace_squared = workspace_radius_m * workspace_radius_m;
  std::size_t valid = 0, far = 0, outside = 0;
  const PointT* first_far = nullptr;
  Eigen::Vector3d first_outside = Eigen::Vector3d::Zero();
  for (const auto& p : f.cloud->points) {
    if (!is_valid(p)) continue;
    ++valid;
    if (p.getVector3fMap().squaredNorm() > kMaxPointRangeM * kMaxPointRangeM && far++ == 0) first_far = &p;
    const Eigen::Vector3d p_world = T * p.getVector3fMap().cast<double>();
    if (p_world.squaredNorm() > workspace_squared && outside++ == 0) first_outside = p_world;
  }
  if (valid == 0) return invalid_argument(where + ": no valid points (all NaN or non-finite)");
  if (far > 0) {
    return invalid_argument(where + ": " + std::to_string(far) + " points lie farther than " +
                            std::to_string(static_cast<int>(kMaxPointRangeM)) + " m from the sensor (the first at " +
                            std::to_string(first_far->x) + " " + std::to_string(first_far->y) + " " +
                            std::to_string(first_far->z) + "): coordinates must be metres in the camera frame");
  }
  if (outside > 0) {
    std::ostringstream at;
    at << first_outside.x() << " " << first_outside.y() << " " << first_outside.z();
    return invalid_argument(where + ": " + std::to_string(outside) + " points lie " + workspace + " (the first at " +
                            at.str() + " in the world)");
  }
  if (!std::isfinite(f.stamp_s)) return invalid_argument(where + ": stamp is not finite");
  if (auto st = validate_camera_name(f.camera, where); !st) return st.error();
  if (f.intrinsics) {
    const Intrinsics& K = *f.intrinsics;
    if (!K.valid()) return invalid_argument(where + ": intrinsics are invalid");
    if (f.cloud->height > 1 && (static_cast<int>(f.cloud->width) != K.width || static_cast<int>(f.cloud->height) != K.height)) {
      return invalid_argument(where + ": intrinsics are for " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                              ", the organized cloud is " + std::to_string(f.cloud->width) + "x" + std::to_string(f.cloud->height));
    }
  }
  return valid;
}

Plane to_world(Plane p, const Pose& T) {
  p.normal = T.linear() * p.normal;
  p.centroid = T * p.centroid;
  for (auto& h : p.hull) h = T * h;
  p.d = -p.normal.dot(p.centroid);
  return p;
}

ObjectCluster to_world(ObjectCluster c, const Pose& T) {
  c.centroid = T * c.centroid;
  c.box.center = T * c.box.center;
  c.box.rotation = Eigen::Quaterniond(T.linear()) * c.box.rotation;
  return c;
}

constexpr std::size_t kSamplesPerObject = 200;
constexpr std::size_t kPointsPerObject = 4000;  // kept per object for the ontology's describe()

// World sample points of each cluster, for the tracker's free-space evidence; clusters the
// foreground claimed are left out.
std::vector<TrackerObservation> tracker_observations(const std::vector<ObjectCluster>& objects, const Cloud& cloud,
                                                     const Pose& T, const std::vector<std::size_t>& claimed) {
  std::vector<TrackerObservation> observations;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (std::find(claimed.begin(), claimed.end(), i) != claimed.end()) continue;
    TrackerObservation o;
    const auto& idx = objects[i].indices;
    const std::size_t step = std::max<std::size_t>(1, idx.size() / kSamplesPerObject);
    for (std::size_t k = 0; k < idx.size(); k += step)
      o.samples.push_back(T * cloud.points[static_cast<std::size_t>(idx[k])].getVector3fMap().cast<double>());
    auto points = std::make_shared<std::vector<Eigen::Vector3d>>();
    const std::size_t every = std::max<std::size_t>(1, idx.size() / kPointsPerObject);
    for (std::size_t k = 0; k < idx.size(); k += every)
      points->push_back(T * cloud.points[static_cast<std::size_t>(idx[k])].getVector3fMap().cast<double>());
    o.points = std::move(points);
    o.cluster = objects[i];
    o.range_m = (objects[i].centroid - T.translation()).norm();
    observations.push_back(std::move(o));
  }
  return observations;
}

// A box that lies for the most part (half its volume or more) in one of the frame's hands or arms,
// each grown by `margin_m`: a finger or a sleeve, not an object the hand reaches for.
bool touches_hand(const Aabb& box, const HandsSeen& hands, double margin_m) {
  const double volume = (box.max - box.min).cwiseMax(1e-6).prod();
  for (const auto& h : hands.hands) {
    const Eigen::Vector3d lo = (h.box_world.min.array() - margin_m).max(box.min.array());
    const Eigen::Vector3d hi = (h.box_world.max.array() + margin_m).min(box.max.array());
    if ((hi.array() > lo.array()).all() && (hi - lo).prod() >= 0.5 * volume) return true;
  }
  return false;
}

// The share of `points` (world) an organized frame sees where they are: in its image, with the
// frame's depth there within the sensor's 3 sigma plus a voxel of theirs.
double seen_in_place(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                     const std::vector<Eigen::Vector3d>& points) {
  if (!K || cloud.height <= 1 || points.empty() || static_cast<int>(cloud.width) != K->width) return 0.0;
  const Pose T_camera_world = T.inverse();
  std::size_t n = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d q = T_camera_world * p;
    if (q.z() <= 0) continue;
    const long u = std::lround(K->fx * q.x() / q.z() + K->cx), v = std::lround(K->fy * q.y() / q.z() + K->cy);
    if (u < 0 || v < 0 || u >= static_cast<long>(cloud.width) || v >= static_cast<long>(cloud.height)) continue;
    const PointT& f = cloud.points[static_cast<std::size_t>(v) * cloud.width + static_cast<std::size_t>(u)];
    if (!is_valid(f)) continue;
    n += std::abs(f.z - q.z()) < 3 * config.sensor.sigma_z(q.z()) + config.segmentation.voxel_size_m;
  }
  return static_cast<double>(n) / static_cast<double>(points.size());
}

// Objects stand on tables, shelves and floors, not on walls: the clusters whose supporting plane
// faces more than 45 degrees away from the world's up (up_direction's own bound) are a wall's
// relief (a whiteboard, a poster, a socket), not objects to list. Their space is never seen free,
// so the list would only grow: hrt1's pick_toy_2 ended with 60 objects, most of them pieces of
// the wall behind the table.
void keep_on_level_supports(std::vector<TrackerObservation>& observations, const std::vector<Plane>& planes,
                            const Eigen::Vector3d& up, const Eigen::Vector3d& camera) {
  const auto level = [&](int plane_id) {
    for (const auto& p : planes)
      if (p.id == plane_id) return faces_within_45_degrees(p, camera, up);
    return true;  // no plane to judge by
  };
  observations.erase(std::remove_if(observations.begin(), observations.end(),
                                    [&](const TrackerObservation& o) { return !level(o.cluster.plane_id); }),
                     observations.end());
}

// The frame without the points of unconfirmed change candidates: an added candidate's own points,
// and every pixel in the region where a removed candidate was seen through (a few pixels wider).
// Without this the insertion would erode a removed object's voxels frame by frame, and the
// candidate would change shape (and lose its move partner) before it is confirmed.
CloudConstPtr without_pending(const Cloud& cloud, const std::vector<change::ChangeCluster>& pending,
                              const Intrinsics& K) {
  auto masked = std::make_shared<Cloud>(cloud);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto blank = [&](std::size_t i) { masked->points[i].x = masked->points[i].y = masked->points[i].z = nan; };
  constexpr int kMarginPx = 3;
  for (const auto& c : pending) {
    if (c.kind == change::ChangeKind::kAdded) {
      for (int i : c.indices) blank(static_cast<std::size_t>(i));
      continue;
    }
    const int u0 = c.region.x - kMarginPx, v0 = c.region.y - kMarginPx;
    const int u1 = c.region.x + c.region.width + kMarginPx, v1 = c.region.y + c.region.height + kMarginPx;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const PointT& p = cloud.points[i];
      if (!is_valid(p) || p.z <= 0) continue;
      const bool organized = cloud.height > 1;
      const int u = organized ? static_cast<int>(i % cloud.width) : static_cast<int>(std::lround(K.fx * p.x / p.z + K.cx));
      const int v = organized ? static_cast<int>(i / cloud.width) : static_cast<int>(std::lround(K.fy * p.y / p.z + K.cy));
      if (u >= u0 && u <= u1 && v >= v0 && v <= v1) blank(i);
    }
  }
  return masked;
}

// The camera a frame is seen with: its intrinsics, else recovered from its organized cloud (or a
// virtual one for an unorganized cloud; change::observation_camera). Found once per frame.
std::optional<Intrinsics> frame_camera(const Frame& frame) {
  auto K = change::observation_camera(*frame.cloud, frame.intrinsics);
  if (!K) return std::nullopt;
  return *K;
}

// How many pixels apart an organized frame seen by camera K may be sampled for work on a grid of
// `spacing_m`: at most `most`, and only as coarse as keeps the samples within one grid cell of each
// other on a surface facing the camera at `range_m` (a VGA Kinect: 2 for the segmentation's 1 cm
// at 2 m and for the map's 2 cm at 5 m; 320x240: 1).
int sample_stride(const Frame& frame, const std::optional<Intrinsics>& K, double spacing_m, double range_m, int most) {
  if (most <= 1 || frame.cloud->height <= 1 || !(range_m > 0) || !K) return 1;
  return std::clamp(static_cast<int>(std::floor(spacing_m * std::min(K->fx, K->fy) / range_m)), 1, most);
}

// How far from the camera a frame sampled on every second pixel (or coarser) is segmented for the
// object list: the tracker's workspace (objects whose centroid lies farther are not objects) and
// half a metre more, for the far side of an object at its edge and for the plane it stands on.
// A room frame's far walls and floor were two thirds of its segmentation (7-Scenes kitchen: 41.6
// -> 14.6 ms in `scenewatch replay`). Frames segmented on every pixel (320x240) stay whole.
double workspace_range(const TrackingConfig& tracking) { return tracking.max_range_m + 0.5; }

}  // namespace

/// What geometric change detection made of one frame.
struct ChangeOutcome {
  std::vector<change::ChangeCluster> pending;   ///< unconfirmed candidates seen in this frame
  std::vector<change::ChangeCluster> absorbed;  ///< more of changes already confirmed
  std::vector<change::ObjectChange> confirmed;  ///< confirmed by this frame
  Intrinsics K;                                 ///< the camera the frame was compared with
};

struct WorkingMemory::Impl {
  explicit Impl(const Config& c)
      : map(c.background), witness(c.background.resolution_m), appearance(c.appearance, c.surprise),
        localizer(c.localization, c.sensor), changes(c.change),
        tracker(c.tracking), fusion(c.fusion),
        foreground(c.foreground), snapshot(std::make_shared<SceneSnapshot>()), up(c.segmentation.up) {}

  // process() and the other writers hold this for their whole duration.
  mutable std::mutex writer;
  // Guards `map` between writers and concurrent occupancy readers.
  mutable std::shared_mutex map_mutex;
  background::OccupancyMap map;
  background::DenseGrid map_grid;  // the change detector's dense copy of the map, its buffers kept between frames
  change::SurfaceWitness witness;  // which cameras saw each surface of the map (guarded with it)
  AppearanceStage appearance;  // keyframes, mesh and image surprise; locks itself for readers
  localization::Localizer localizer;  // where each camera is, against the keyframes (writer only)

  // Owned by the writer.
  change::PersistenceFilter changes;
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

  // Known surfaces of described objects (set_known_surface), by object id.
  struct Known {
    Eigen::Vector3d centroid_world;
    std::shared_ptr<const surprise::KnownSurface> surface;
  };
  std::mutex known_mutex;
  std::map<std::uint64_t, Known> known;

  /// The known surfaces of objects still in the last snapshot within 2 cm of where they were
  /// described; the others are forgotten.
  std::vector<std::shared_ptr<const surprise::KnownSurface>> current_known_surfaces() {
    constexpr double kMovedM = 0.02;
    const auto scene = std::atomic_load(&snapshot);
    std::lock_guard<std::mutex> lock(known_mutex);
    std::vector<std::shared_ptr<const surprise::KnownSurface>> out;
    for (auto it = known.begin(); it != known.end();) {
      const auto object = std::find_if(scene->objects.begin(), scene->objects.end(),
                                       [&](const TrackedObject& o) { return o.id == it->first; });
      if (object == scene->objects.end() || (object->cluster.centroid - it->second.centroid_world).norm() > kMovedM) {
        it = known.erase(it);
        continue;
      }
      out.push_back(it->second.surface);
      ++it;
    }
    return out;
  }

  mutable std::mutex events_mutex;
  std::deque<Event> events;
  std::uint64_t next_event_id = 1;
  std::uint64_t events_emitted = 0;
  std::map<int, EventCallback> subscribers;
  int next_token = 1;

  std::optional<Eigen::Vector3d> up;  // the configured up direction (segmentation.up_vector)

  void publish() {
    auto s = std::make_shared<SceneSnapshot>();
    s->frames_processed = frames;
    s->planes = planes;
    s->objects = tracker.objects();
    for (auto& o : foreground.tracker().objects()) s->objects.push_back(std::move(o));
    s->hands = foreground.hands();
    for (const auto& o : tracker.objects()) {
      if (auto p = tracker.points(o.id)) s->points[o.id] = std::move(p);
    }
    for (const auto& o : foreground.tracker().objects()) {
      if (auto model = foreground.tracker().model(o.id)) {
        auto p = std::make_shared<std::vector<Eigen::Vector3d>>();
        for (const auto& q : model->points) p->push_back(o.foreground->T_world_object * q.getVector3fMap().cast<double>());
        s->points[o.id] = std::move(p);
      }
    }
    s->up_world = up_direction(up, planes, last_camera);
    s->camera_world = last_camera.translation();
    s->last_stamp_s = last_stamp_s;
    std::atomic_store(&snapshot, std::shared_ptr<const SceneSnapshot>(std::move(s)));
  }

  // Geometric change detection against the map as it stands before this frame. Candidates stay
  // out of the map until the persistence filter confirms them, so the comparison keeps being made
  // against the model that predates them (OctoMap's log-odds would absorb a new object, or erode
  // a removed one, within a few frames). A frame whose region is too large for a dense grid is
  // left without change detection.
  ChangeOutcome detect_changes(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K,
                               const change::Config& config, std::uint32_t camera) {
    ChangeOutcome out;
    if (!K) return out;
    out.K = *K;
    std::shared_lock<std::shared_mutex> read(map_mutex);
    auto mismatch = change::mismatch_against_map(map, *frame.cloud, T, *K, config, &map_grid,
                                                 config.witness_per_camera ? &witness : nullptr, camera);
    if (!mismatch) return out;
    change::ClusterInput input;
    input.after_camera = frame.cloud.get();
    input.T_world_after = T;
    input.K_after = *K;
    out.confirmed = changes.update(change::cluster_mismatch(*mismatch, input, config), &out.pending, &out.absorbed, camera);
    return out;
  }

  // The object list (no events: a change is reported by the change detector, once); the
  // foreground's objects are not background objects.
  void track_objects(const FrameResult& result, const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K,
                     const std::vector<std::size_t>& claimed, const Config& config) {
    const std::optional<Eigen::Vector3d>& configured_up = config.segmentation.up;
    std::vector<TrackerObservation> observations = tracker_observations(result.objects, *frame.cloud, T, claimed);
    const HandsSeen& hands = foreground.hands();
    for (auto& o : observations) {
      o.resolution_m = std::max(config.segmentation.voxel_size_m, 2 * config.sensor.sigma_z(o.range_m));
      if (hands.frame_index == frames) o.touches_person = touches_hand(o.cluster.box.aabb(), hands, config.segmentation.cluster_tolerance_m);
    }
    // Only with an up to trust: a largest plane taken for want of a level one may be a wall.
    if (const auto up = level_up(configured_up, result.planes, T)) keep_on_level_supports(observations, result.planes, *up, T.translation());
    std::shared_lock<std::shared_mutex> read(map_mutex);
    tracker.update(std::move(observations), frame.stamp_s, [&](const std::vector<Eigen::Vector3d>& pts) {
      if (pts.empty()) return 0.0;
      std::size_t n = 0;
      for (const auto& p : pts) n += (map.freed_by_last_insert(p) || map.query(p) == background::Occupancy::kFree) ? 1 : 0;
      return static_cast<double>(n) / pts.size();
    }, [&](const std::vector<Eigen::Vector3d>& pts) { return seen_in_place(*frame.cloud, T, K, config, pts); });
  }

  // Change detection against the map as it stands before this frame, then the frame into the
  // map (without the points of unconfirmed candidates); confirmed changes are written into it at
  // once. Runs beside the segmentation and the image surprise, which do not read the map.
  ChangeOutcome update_map(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                           FrameResult& result, std::uint32_t camera) {
    ChangeOutcome changed;
    if (config.change_enabled && frames > 0) {
      const auto t_change = Clock::now();
      changed = detect_changes(frame, T, K, config.change, camera);
      result.change_ms = ms_since(t_change);
      result.change_candidates = changes.candidates();
    }
    CloudConstPtr to_insert = frame.cloud;
    if (!changed.pending.empty()) to_insert = without_pending(*frame.cloud, changed.pending, changed.K);
    const auto t_ins = Clock::now();
    const background::Config& b = config.background;
    const int stride = sample_stride(frame, K, b.resolution_m, b.max_range_m, b.insert_stride_px);
    std::unique_lock<std::shared_mutex> write(map_mutex);
    result.insert_stats = map.insert(*to_insert, T, stride);
    witness.witness(*to_insert, T, camera, stride);
    for (const auto& c : changed.confirmed) {
      if (c.before) {
        map.set_voxels(c.before->points_world, background::Occupancy::kFree);
        witness.forget(c.before->points_world);
      }
      if (c.after) map.set_voxels(c.after->points_world, background::Occupancy::kOccupied);
    }
    for (const auto& c : changed.absorbed) {
      map.set_voxels(c.points_world, c.kind == change::ChangeKind::kAdded ? background::Occupancy::kOccupied
                                                                          : background::Occupancy::kFree);
    }
    result.insert_ms = ms_since(t_ins);
    return changed;
  }

  // The share of world points on surfaces the map remembers (occupied), for the foreground.
  ForegroundStage::OccupiedFraction occupied_fraction(const change::Config& change_config) {
    return [this, change_config](const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& camera) {
      std::shared_lock<std::shared_mutex> read(map_mutex);
      const double step = 0.5 * map.resolution();
      std::size_t n = 0;
      for (const auto& p : pts) {
        const Eigen::Vector3d ray = p - camera;
        const double range = ray.norm();
        const double reach = change::map_tolerance_m(change_config, range);
        bool on = map.query(p) == background::Occupancy::kOccupied;
        for (double t = step; !on && range > 0 && t <= reach + 1e-9; t += step) {
          const Eigen::Vector3d d = (t / range) * ray;
          on = map.query(p + d) == background::Occupancy::kOccupied || map.query(p - d) == background::Occupancy::kOccupied;
        }
        n += on ? 1 : 0;
      }
      return pts.empty() ? 0.0 : static_cast<double>(n) / pts.size();
    };
  }

  // One fact, one event: appearance regions where geometry changes are its evidence; others must
  // persist. What the foreground explains (a carried object's old and new place) is not a change.
  std::vector<Event> fuse(const FrameResult& result, const ChangeOutcome& changed, const std::vector<Aabb>& quiet,
                          double stamp_s, std::uint32_t camera) {
    auto explained = [&](const Aabb& box) {
      return std::any_of(quiet.begin(), quiet.end(), [&](const Aabb& q) { return q.overlaps(box); });
    };
    std::vector<Event> geometric;
    std::vector<Aabb> boxes;  // both places of a move
    for (const auto& c : changed.confirmed) {
      Event e = change::to_event(c);
      if (explained(e.box_world)) continue;
      e.stamp_s = stamp_s;
      geometric.push_back(std::move(e));
      if (c.before) boxes.push_back(c.before->box_world);
      if (c.after) boxes.push_back(c.after->box_world);
    }
    std::vector<Event> appearance;
    if (result.surprise) {
      for (const auto& e : result.surprise->events)
        if (!explained(e.box_world)) appearance.push_back(e);
    }
    const bool familiar = result.surprise && result.surprise->familiar_view;
    return fusion.update(appearance, changed.pending, std::move(geometric), std::move(boxes), familiar, tracker.objects(),
                         result.objects, camera);
  }

  // The id of the frame's camera; a camera forgotten to make room takes its per-camera state along.
  std::uint32_t camera_of(const Frame& frame) {
    std::optional<std::uint32_t> forgotten;
    const std::uint32_t id = cameras.id(frame.camera, &forgotten);
    if (forgotten) {
      changes.forget_camera(*forgotten);
      fusion.forget_camera(*forgotten);
      foreground.forget_camera(*forgotten);
      appearance.forget_camera(*forgotten);
      localizer.forget_camera(*forgotten);
      planes_by_camera.erase(*forgotten);
    }
    return id;
  }

  void emit(std::vector<Event>& batch, std::size_t max_log) {
    std::vector<EventCallback> callbacks;
    {
      std::lock_guard<std::mutex> lock(events_mutex);
      for (auto& e : batch) {
        e.id = next_event_id++;
        events.push_back(e);
        ++events_emitted;
      }
      while (events.size() > max_log) events.pop_front();
      for (const auto& [token, cb] : subscribers) callbacks.push_back(cb);
    }
    for (const auto& e : batch)
      for (const auto& cb : callbacks) cb(e);
  }
};

Status validate(const Config& c) {
  if (auto st = scenewatch::validate(c.sensor); !st) return st;
  if (auto st = background::validate(c.background); !st) return st;
  if (auto st = segmentation::validate(c.segmentation); !st) return st;
  if (!(c.tracking.match_distance_m > 0 && c.tracking.match_distance_m < 5)) return invalid_argument("tracking.match_distance_m: must be in (0, 5) m");
  if (!(c.tracking.gone_free_fraction > 0 && c.tracking.gone_free_fraction <= 1)) return invalid_argument("tracking.gone_free_fraction: must be in (0, 1]");
  if (c.tracking.confirm_frames < 1 || c.tracking.confirm_frames > 100) return invalid_argument("tracking.confirm_frames: must be in [1, 100]");
  if (!(c.tracking.min_extent_cells >= 0 && c.tracking.min_extent_cells <= 100))
    return invalid_argument("tracking.min_extent_cells: must be in [0, 100]");
  if (c.tracking.gone_frames < 1 || c.tracking.gone_frames > 100) return invalid_argument("tracking.gone_frames: must be in [1, 100]");
  if (!(c.tracking.max_range_m > 0 && c.tracking.max_range_m <= 20)) return invalid_argument("tracking.max_range_m: must be in (0, 20] m");
  if (c.tracking.segmentation_stride_px < 1 || c.tracking.segmentation_stride_px > 8)
    return invalid_argument("tracking.segmentation_stride_px: must be in [1, 8]");
  if (c.max_event_log < 1) return invalid_argument("events.max_log: must be >= 1");
  if (c.fusion.persistence_frames < 1 || c.fusion.persistence_frames > 100) return invalid_argument("events.appearance_persistence_frames: must be in [1, 100]");
  if (!(c.fusion.match_m > 0 && c.fusion.match_m <= 1)) return invalid_argument("events.appearance_match_m: must be in (0, 1] m");
  if (!(c.fusion.margin_m >= 0 && c.fusion.margin_m <= 1)) return invalid_argument("events.merge_margin_m: must be in [0, 1] m");
  if (c.fusion.zone_frames < 0 || c.fusion.zone_frames > 100000) return invalid_argument("events.silence_frames: must be in [0, 100000]");
  if (!(c.workspace_radius_m > 0 && c.workspace_radius_m <= 100000))
    return invalid_argument("workspace.radius_m: must be in (0, 100000] m, got " + metres(c.workspace_radius_m));
  if (auto st = background::validate(c.appearance); !st) return st;
  if (auto st = surprise::validate(c.surprise); !st) return st;
  if (auto st = change::validate(c.change); !st) return st;
  if (auto st = foreground::validate(c.foreground); !st) return st;
  if (auto st = localization::validate(c.localization); !st) return st;
  return {};
}

namespace {
// The keyframes' features in a snapshot folder (localization::save_features).
constexpr const char* kFeaturesFile = "keyframe-features.bin";

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

WorkingMemory::WorkingMemory(Config config) : config_(with_sensor(std::move(config))), impl_(std::make_unique<Impl>(config_)) {}
WorkingMemory::~WorkingMemory() = default;

Result<FrameResult> WorkingMemory::process(const Frame& original) {
  const auto valid_points = validate_frame(original, config_.workspace_radius_m);
  if (!valid_points) return valid_points.error();
  const auto t0 = Clock::now();
  std::lock_guard<std::mutex> lock(impl_->writer);
  Impl& m = *impl_;
  FrameResult result;
  result.frame_index = m.frames;
  result.points = *valid_points;
  const std::uint32_t camera_id = m.camera_of(original);
  // Where the frame was taken, against the memory; a camera that is lost changes nothing.
  result.localization = m.localizer.localize(
      original, camera_id, [&](const Pose& p, std::size_t n) { return m.appearance.nearest(p, n); },
      [&] { return m.appearance.all_keyframes(); });
  if (!result.localization.placed()) {
    ++m.frames;
    result.total_ms = ms_since(t0);
    return result;
  }
  const Frame frame = placed(original, result.localization);
  const Pose T = frame.pose_or_identity();
  // Hands, the person and the foreground objects are blanked out of what the background sees.
  // The planes this camera saw last (world frame); a camera's first frame starts from the model's.
  const auto own_planes = m.planes_by_camera.find(camera_id);
  const Frame seen = m.foreground.prepare(frame, m.frames, own_planes != m.planes_by_camera.end() ? own_planes->second : m.planes,
                                          config_.segmentation.up, m.occupied_fraction(config_.change), result, camera_id);

  // Three independent parts, each against the memory as it stands before this frame: the
  // geometric change detection with the map update (the octree), the image surprise (keyframes
  // and mesh) and the segmentation of the frame. None reads what another writes; the tracker and
  // the event fusion below need all three. Two threads for two cores: the map's part, the longest
  // (the insertion must wait for the change detection), on one; the other two one after the
  // other on this one. Three threads made the three share two cores, and the map's part, which
  // the frame waits for, ran at two thirds of a core (kitchen 76.6 -> 57.0 ms per frame).
  const auto known_surfaces = m.current_known_surfaces();
  const std::optional<Intrinsics> camera = frame_camera(seen);
  const auto t_parallel = Clock::now();
  auto map_update = std::async(std::launch::async, [&] { return m.update_map(seen, T, camera, config_, result, camera_id); });
  {
    const auto t_surprise = Clock::now();
    result.surprise = m.appearance.process(seen, known_surfaces, camera_id);  // then its keyframe update
    result.surprise_ms = ms_since(t_surprise);
  }

  // Segment in the camera frame (indices stay those of the input cloud), then move to the world.
  segmentation::Config seg = config_.segmentation;
  if (seg.up) seg.up = T.linear().transpose() * *seg.up;
  const auto t_seg = Clock::now();
  const int stride =
      sample_stride(seen, camera, seg.voxel_size_m, config_.tracking.max_range_m, config_.tracking.segmentation_stride_px);
  segmentation::Segmentation s =
      segmentation::segment_strided(*seen.cloud, seg, Eigen::Vector3d::Zero(), stride, workspace_range(config_.tracking));
  result.segment_ms = ms_since(t_seg);
  for (auto& p : s.planes) result.planes.push_back(to_world(std::move(p), T));
  for (auto& o : s.objects) result.objects.push_back(to_world(std::move(o), T));

  const ChangeOutcome changed = map_update.get();
  result.parallel_ms = ms_since(t_parallel);
  const auto t_after = Clock::now();
  foreground::ForegroundUpdate fg = m.foreground.update(result.objects, m.tracker.objects(), result);
  result.events = m.fuse(result, changed, fg.quiet_boxes, frame.stamp_s, camera_id);

  m.track_objects(result, frame, T, camera, fg.claimed_clusters, config_);
  for (std::uint64_t id : fg.promoted) m.tracker.remove(id);
  if (!fg.vacated.empty()) {
    // A promoted object's old place is empty now: its removal is explained, not a surprise.
    std::unique_lock<std::shared_mutex> write(m.map_mutex);
    for (const auto& pts : fg.vacated) m.map.set_voxels(pts, background::Occupancy::kFree);
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
  m.emit(result.events, config_.max_event_log);
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
    s.tracked_objects = impl_->tracker.objects().size();
    s.keyframes = impl_->appearance.keyframes();
    s.mesh_triangles = impl_->appearance.triangles();
    s.appearance_memory_bytes = impl_->appearance.memory_bytes();
    std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
    s.map_leaf_nodes = impl_->map.num_leaf_nodes();
    s.map_occupied_leaves = impl_->map.num_occupied_leaves();
    s.map_memory_bytes = impl_->map.memory_bytes();
    s.map_resolution_m = impl_->map.resolution();
  }
  std::lock_guard<std::mutex> lock(impl_->events_mutex);
  s.events_emitted = impl_->events_emitted;
  return s;
}

background::Occupancy WorkingMemory::query(const Eigen::Vector3d& p) const {
  std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
  return impl_->map.query(p);
}

OccupiedVoxels WorkingMemory::occupied_voxels(std::size_t max_count) const {
  OccupiedVoxels out;
  {
    std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
    out.centers_world = impl_->map.occupied_voxel_centers();
    out.resolution_m = impl_->map.resolution();
  }
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
  std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
  out.data = impl_->map.binary_data();
  out.resolution_m = impl_->map.resolution();
  out.nodes = impl_->map.num_nodes();
  out.leaf_nodes = impl_->map.num_leaf_nodes();
  return out;
}

background::BoxOccupancy WorkingMemory::query_box(const Aabb& box) const {
  std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
  return impl_->map.query_box(box);
}

Result<background::DenseGrid> WorkingMemory::dense_grid(const Aabb& box, std::size_t max_voxels) const {
  std::shared_lock<std::shared_mutex> read(impl_->map_mutex);
  return impl_->map.dense_grid(box, max_voxels);
}

std::size_t WorkingMemory::clear_box(const Aabb& box) {
  std::lock_guard<std::mutex> lock(impl_->writer);
  std::unique_lock<std::shared_mutex> write(impl_->map_mutex);
  return impl_->map.clear_box(box);
}

void WorkingMemory::reset() {
  std::lock_guard<std::mutex> lock(impl_->writer);
  {
    std::unique_lock<std::shared_mutex> write(impl_->map_mutex);
    impl_->map.reset();
    impl_->witness.reset();
  }
  impl_->appearance.reset();
  impl_->localizer.reset();
  {
    std::lock_guard<std::mutex> known_lock(impl_->known_mutex);
    impl_->known.clear();
  }
  impl_->tracker.reset();
  impl_->changes.reset();
  impl_->fusion.reset();
  impl_->foreground.reset();
  impl_->planes.clear();
  impl_->planes_by_camera.clear();
  impl_->cameras.reset();
  impl_->last_camera = Pose::Identity();
  impl_->frames = impl_->points = 0;
  impl_->total_ms = impl_->last_ms = 0;
  impl_->last_stamp_s = 0.0;
  {
    // The log goes too (Reset forgets everything); ids keep counting, so none is given twice.
    std::lock_guard<std::mutex> events_lock(impl_->events_mutex);
    impl_->events.clear();
  }
  impl_->publish();
}

namespace {

// Loads the background map and checks it against what scene.json recorded when it was saved (its
// size in bytes and its leaf count): a damaged file is refused, not loaded in part and then saved
// over the model. Models saved before the record existed are loaded unchecked.
Status load_background(background::OccupancyMap& map, const fs::path& path, const nlohmann::json& scene) {
  const auto record = scene.is_object() ? scene.find("background") : scene.end();
  if (record != scene.end() && !record->is_object()) {
    return invalid_argument("'" + path.string() + "': the model's scene.json records its background as " +
                            std::string(record->type_name()) + ", not an object with bytes and leaf_nodes");
  }
  if (record != scene.end()) {
    std::error_code ec;
    const auto bytes = fs::file_size(path, ec);
    if (ec) return io_error("'" + path.string() + "': " + ec.message());
    const auto expected = record->value("bytes", std::uint64_t{0});
    if (bytes != expected) {
      return invalid_argument("'" + path.string() + "': damaged: " + std::to_string(bytes) + " bytes, the model recorded " +
                              std::to_string(expected) + " when it was saved");
    }
  }
  if (auto st = map.load(path); !st) return st;
  if (record != scene.end()) {
    const auto leaves = record->value("leaf_nodes", std::uint64_t{0});
    if (map.num_leaf_nodes() != leaves) {
      return invalid_argument("'" + path.string() + "': damaged: " + std::to_string(map.num_leaf_nodes()) +
                              " leaf nodes, the model recorded " + std::to_string(leaves));
    }
  }
  return {};
}

}  // namespace

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
    std::size_t map_leaves = 0;
    {
      std::shared_lock<std::shared_mutex> read(m.map_mutex);
      if (auto st = m.map.save(dir / "background.ot"); !st) return st;
      map_leaves = m.map.num_leaf_nodes();
    }
    // What the map file must be on load: OctoMap reads a truncated .ot without complaint.
    std::error_code ec;
    const auto map_bytes = fs::file_size(dir / "background.ot", ec);
    if (ec) return io_error("'" + (dir / "background.ot").string() + "': " + ec.message());
    nlohmann::json scene = {{"format", "scenewatch-model"}, {"version", 1}, {"frames_processed", m.frames},
                            {"points_processed", m.points}, {"next_object_id", m.tracker.next_id()},
                            {"last_stamp_s", m.last_stamp_s},
                            {"background", {{"bytes", map_bytes}, {"leaf_nodes", map_leaves}}}};
    scene["objects"] = nlohmann::json::array();
    for (const auto& o : m.tracker.objects()) {
      nlohmann::json j = to_json(o);
      nlohmann::json pts = nlohmann::json::array();
      if (const auto* samples = m.tracker.samples(o.id))
        for (const auto& p : *samples) pts.push_back({p.x(), p.y(), p.z()});
      j["samples"] = pts;
      scene["objects"].push_back(j);
    }
    // Foreground objects with their point models (object frame: x y z r g b), so that a restarted
    // daemon tracks them and keeps their learnt DoFs.
    scene["foreground"] = nlohmann::json::array();
    for (const auto& o : m.foreground.tracker().objects()) {
      nlohmann::json j = to_json(o);
      nlohmann::json pts = nlohmann::json::array();
      if (auto model = m.foreground.tracker().model(o.id))
        for (const auto& p : model->points) pts.push_back({p.x, p.y, p.z, p.r, p.g, p.b});
      j["model"] = pts;
      scene["foreground"].push_back(j);
    }
    scene["planes"] = nlohmann::json::array();
    for (const auto& p : m.planes) scene["planes"].push_back(to_json(p));
    std::string log;
    {
      std::lock_guard<std::mutex> events_lock(m.events_mutex);
      scene["next_event_id"] = m.next_event_id;
      for (const auto& e : m.events) {
        nlohmann::json j = to_json(e);
        j.erase("indices_before");  // indices into frames the model no longer holds
        j.erase("indices_after");
        log += j.dump() + "\n";
      }
    }
    if (auto st = m.appearance.save(dir); !st) return st;
    // The keyframes' features, for relocalization (homing) after a restart.
    if (auto st = localization::save_features(dir / kFeaturesFile, m.localizer.relocalizer().to_save(m.appearance.all_keyframes())); !st)
      return st;
    if (auto st = write_file_synced(dir / "scene.json", scene.dump(2)); !st) return st;
    return write_file_synced(dir / "events.jsonl", log);
  }, keep_snapshots);
}

Status WorkingMemory::load(const fs::path& model_dir) {
  auto dir = current_snapshot(model_dir);
  if (!dir) return dir.error();
  return load_snapshot(*dir);
}

Result<LoadedSnapshot> WorkingMemory::load_newest_good(const fs::path& model_dir) {
  auto current = current_snapshot(model_dir);
  if (!current && current.error().code == ErrorCode::kNotFound) return current.error();
  LoadedSnapshot report;
  std::vector<fs::path> candidates;
  if (current) candidates.push_back(*current);
  for (const auto& snap : snapshots_newest_first(model_dir)) {
    if (!current || snap.filename() != current->filename()) candidates.push_back(snap);
  }
  for (const auto& snap : candidates) {
    if (auto st = load_snapshot(snap); !st) {
      report.refused.push_back(st.error().message);
      continue;
    }
    report.folder = snap;
    return report;
  }
  if (!current) report.refused.insert(report.refused.begin(), current.error().message);
  std::string why;
  for (const auto& r : report.refused) why += (why.empty() ? "" : "; ") + r;
  return invalid_argument("'" + model_dir.string() + "': no snapshot loads: " + why);
}

Status WorkingMemory::load_snapshot(const fs::path& dir) {
  // Build everything aside first: a bad file leaves the model as it was.
  std::ifstream in(dir / "scene.json");
  if (!in) return io_error("'" + (dir / "scene.json").string() + "': cannot open");
  nlohmann::json scene;
  try {
    scene = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    return invalid_argument("'" + (dir / "scene.json").string() + "': " + e.what());
  }
  background::OccupancyMap map(config_.background);
  try {
    if (auto st = load_background(map, dir / "background.ot", scene); !st) return st;
  } catch (const std::exception& e) {  // a record of the wrong type: json's type_error
    return invalid_argument("'" + (dir / "scene.json").string() + "': malformed background record: " + e.what());
  }
  std::vector<TrackedObject> objects;
  std::map<std::uint64_t, std::vector<Eigen::Vector3d>> samples;
  std::vector<Plane> planes;
  std::vector<std::pair<TrackedObject, CloudConstPtr>> foreground;
  std::deque<Event> events;
  std::uint64_t frames = 0, points = 0, next_object_id = 1, next_event_id = 1;
  double last_stamp_s = 0.0;
  try {
    last_stamp_s = scene.value("last_stamp_s", 0.0);
    frames = scene.at("frames_processed").get<std::uint64_t>();
    points = scene.value("points_processed", std::uint64_t{0});
    next_object_id = scene.at("next_object_id").get<std::uint64_t>();
    next_event_id = scene.value("next_event_id", std::uint64_t{1});
    for (const auto& j : scene.at("objects")) {
      auto o = object_from_json(j);
      if (!o) return o.error();
      for (const auto& p : j.value("samples", nlohmann::json::array()))
        samples[o->id].emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
      objects.push_back(*o);
    }
    for (const auto& j : scene.value("foreground", nlohmann::json::array())) {
      auto o = object_from_json(j);
      if (!o) return o.error();
      if (!o->foreground) return invalid_argument("'" + (dir / "scene.json").string() + "': foreground object " + std::to_string(o->id) + " has no foreground state");
      auto model = std::make_shared<Cloud>();
      for (const auto& p : j.at("model")) {
        PointT q;
        q.x = p.at(0).get<float>(), q.y = p.at(1).get<float>(), q.z = p.at(2).get<float>();
        q.r = p.at(3).get<std::uint8_t>(), q.g = p.at(4).get<std::uint8_t>(), q.b = p.at(5).get<std::uint8_t>();
        model->push_back(q);
      }
      if (model->empty()) return invalid_argument("'" + (dir / "scene.json").string() + "': foreground object " + std::to_string(o->id) + " has an empty model");
      foreground.emplace_back(*o, std::move(model));
    }
    for (const auto& j : scene.at("planes")) {
      auto p = plane_from_json(j);
      if (!p) return p.error();
      planes.push_back(*p);
    }
  } catch (const std::exception& e) {
    return invalid_argument("'" + (dir / "scene.json").string() + "': malformed: " + e.what());
  }
  std::ifstream log(dir / "events.jsonl");
  std::string line;
  while (std::getline(log, line)) {
    if (line.empty()) continue;
    try {
      auto e = event_from_json(nlohmann::json::parse(line));
      if (!e) return e.error();
      events.push_back(*e);
    } catch (const std::exception& ex) {
      return invalid_argument("'" + (dir / "events.jsonl").string() + "': " + ex.what());
    }
  }

  // Keyframe features (absent in models saved before them: extracted again on first use).
  std::vector<localization::SavedFeatures> features;
  if (std::error_code ec; fs::exists(dir / kFeaturesFile, ec)) {
    auto loaded = localization::load_features(dir / kFeaturesFile);
    if (!loaded) return loaded.error();
    features = std::move(*loaded);
  }

  std::lock_guard<std::mutex> lock(impl_->writer);
  Impl& m = *impl_;
  // Keyframes last among the reads: AppearanceStage::load changes nothing when it fails.
  if (auto st = m.appearance.load(dir); !st) return st;
  // Every camera homes anew: its frames are relocalized against the loaded keyframes.
  m.localizer.reset();
  m.localizer.relocalizer().restore(features, m.appearance.all_keyframes());
  {
    std::unique_lock<std::shared_mutex> write(m.map_mutex);
    m.map = std::move(map);
    m.witness = change::SurfaceWitness(m.map.resolution());  // the loaded surfaces: seen by none of this session
  }
  config_.background.resolution_m = m.map.resolution();
  m.tracker.restore(std::move(objects), std::move(samples), next_object_id);
  m.foreground.reset();
  for (const auto& [object, model] : foreground) m.foreground.tracker().restore(object, model);
  m.changes.reset();
  m.fusion.reset();
  m.planes = std::move(planes);
  m.planes_by_camera.clear();
  m.cameras.reset();
  m.frames = frames;
  m.points = points;
  m.last_stamp_s = last_stamp_s;
  {
    std::lock_guard<std::mutex> events_lock(m.events_mutex);
    m.events = std::move(events);
    m.next_event_id = std::max(next_event_id, m.events.empty() ? 1 : m.events.back().id + 1);
  }
  m.publish();
  return {};
}

int WorkingMemory::subscribe(EventCallback callback) {
  std::lock_guard<std::mutex> lock(impl_->events_mutex);
  const int token = impl_->next_token++;
  impl_->subscribers.emplace(token, std::move(callback));
  return token;
}

void WorkingMemory::unsubscribe(int token) {
  std::lock_guard<std::mutex> lock(impl_->events_mutex);
  impl_->subscribers.erase(token);
}

std::vector<Event> WorkingMemory::events_since(std::uint64_t since, std::size_t max_count) const {
  std::lock_guard<std::mutex> lock(impl_->events_mutex);
  std::vector<Event> out;
  for (const auto& e : impl_->events) {
    if (e.id > since && out.size() < max_count) out.push_back(e);
  }
  return out;
}

Result<std::shared_ptr<const SurpriseResult>> WorkingMemory::surprise(const Frame& observation) const {
  if (auto valid = validate_frame(observation, config_.workspace_radius_m); !valid) return valid.error();
  return impl_->appearance.evaluate(observation);
}

std::shared_ptr<const SurpriseResult> WorkingMemory::last_surprise() const { return impl_->appearance.last(); }

Status WorkingMemory::write_mesh(const fs::path& path) const { return impl_->appearance.write_mesh(path); }

void WorkingMemory::set_known_surface(std::uint64_t object_id, const Eigen::Vector3d& centroid_world, surprise::KnownSurface surface) {
  std::lock_guard<std::mutex> lock(impl_->known_mutex);
  if (surface.points_world.empty()) {
    impl_->known.erase(object_id);
    return;
  }
  impl_->known[object_id] = {centroid_world, std::make_shared<const surprise::KnownSurface>(std::move(surface))};
}

}  // namespace scenewatch::pipeline
