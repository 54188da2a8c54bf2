// Touched objects, their promotion to the foreground, their tracking and their handlings: the
// tracker's two steps (track, update), each a list of steps. Its parts have their own files: where
// the hands touch (hand_contact.h), promotion (promotion.h), reacquisition of a lost object
// (reacquisition.h), handlings and the frozen-DoF check (frozen_dof.h), the frame cropped around
// an object (frame_crop.h) and the points they share (object_points.h, touched_object.h).
#include "scenewatch/foreground/foreground_tracker.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <unordered_set>

#include "frame_crop.h"
#include "frozen_dof.h"
#include "hand_contact.h"
#include "object_points.h"
#include "point_model.h"
#include "promotion.h"
#include "reacquisition.h"
#include "skin_model.h"
#include "touched_object.h"
#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {
namespace {

constexpr double kQuietMarginM = 0.05;    // background changes this close to a foreground object are its doing
constexpr int kMinObservations = 3;        // frames a background object was seen before it can be a candidate
constexpr double kStillM = 0.03;           // a candidate moved at most this far since it was first seen
constexpr double kSearchMarginM = 0.08;    // registration targets reach this far beyond the model
constexpr std::size_t kRegistrationPoints = 300;  // model points registration uses

// The support frame: z along `up`, x along the world x (or y) projected on the plane.
Pose support_frame(const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = up.normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z.x() * z;
  if (x.norm() < 0.3) x = Eigen::Vector3d::UnitY() - z.y() * z;
  x.normalize();
  Pose T = Pose::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  return T;
}

// True when more than a few of the cluster's pixels lie beside an arm or a person's body in the
// image (a sleeve, a shoulder): an object is touched by the hand proper, a piece of the person is
// attached to its arm.
bool beside_person(const HandDetection& d, const std::vector<int>& indices, int width, int height) {
  if (d.labels.empty()) return false;
  constexpr int kRadiusPx = 3;
  std::size_t beside = 0, tested = 0;
  const std::size_t step = std::max<std::size_t>(1, indices.size() / 400);
  for (std::size_t k = 0; k < indices.size(); k += step) {
    const int u = indices[k] % width, v = indices[k] / width;
    ++tested;
    bool near = false;
    for (int dv = -kRadiusPx; dv <= kRadiusPx && !near; ++dv) {
      for (int du = -kRadiusPx; du <= kRadiusPx && !near; ++du) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || vv < 0 || uu >= width || vv >= height) continue;
        const AgentLabel l = d.labels[static_cast<std::size_t>(vv * width + uu)];
        near = l == AgentLabel::kArm || l == AgentLabel::kPerson;
      }
    }
    beside += near ? 1 : 0;
  }
  return tested > 0 && 20 * beside > tested;  // more than 5 %
}

// Each touched object's surface (its model where it stands, grown by one voxel, for one lookup
// per point), made once, when first asked for. The objects may grow in number meanwhile; they
// must not move.
class ObjectSurfaces {
 public:
  ObjectSurfaces(const std::vector<TouchedObject>& objects, double voxel_m) : objects_(objects), voxel_m_(voxel_m) {}

  /// True when more than half of the points lie on object k's surface.
  bool mostly_on(std::size_t k, const std::vector<Eigen::Vector3d>& pts) {
    const VoxelSet& surface = of(k);
    std::size_t near = 0;
    for (const auto& p : pts) near += surface.contains(p) ? 1 : 0;
    return 2 * near > pts.size();
  }

 private:
  const VoxelSet& of(std::size_t k) {
    if (surfaces_.size() <= k) surfaces_.resize(objects_.size());
    if (!surfaces_[k]) {
      VoxelSet points(voxel_m_);
      for (const auto& p : posed_points(*objects_[k].model, objects_[k].T)) points.insert(p);
      surfaces_[k] = points.dilated();
    }
    return *surfaces_[k];
  }

  const std::vector<TouchedObject>& objects_;
  double voxel_m_;
  std::vector<std::optional<VoxelSet>> surfaces_;
};

}  // namespace

struct ForegroundTracker::Impl {
  explicit Impl(ForegroundConfig c) : config(std::move(c)) {
    growth.voxel_m = config.model_voxel_m;
    growth.max_points = config.max_model_points;
    growth.max_rmse_m = config.grow_max_rmse_m;
    growth.min_inlier_fraction = config.grow_min_inlier_fraction;
  }

  ForegroundConfig config;
  ModelGrowth growth;
  std::vector<TouchedObject> objects;  // candidates and foreground objects, in the order first touched
  std::map<std::uint64_t, Eigen::Vector3d> first_seen_at;  // background objects: where they were first seen
  Pose T_support = Pose::Identity();

  // The object in this frame: registration targets within its own size (plus a margin for a
  // fast motion) of where it is predicted, the model thinned to what registration needs.
  Registration locate(TouchedObject& o, const FrameView& f, const Pose& guess, Crop& c) {
    double radius = 0;
    for (const auto& p : o.model->points) radius = std::max(radius, static_cast<double>(p.getVector3fMap().norm()));
    radius = std::min(config.search_radius_m, radius + kSearchMarginM + o.velocity.norm());
    c = crop(f, guess.translation(), radius, config.target_voxel_m);
    if (!o.sparse || o.sparse_of != o.model.get()) {
      o.sparse = thinned(*o.model, 0.0, kRegistrationPoints);
      o.sparse_of = o.model.get();
    }
    return register_model(*o.sparse, c.target, guess, f.T_world_camera.translation(), config.registration, f.up_world);
  }

  // The frame's pixels on the registered model.
  std::vector<int> pixels_on(const TouchedObject& o, const Crop& c) const {
    VoxelSet model(config.mask_m);
    for (const auto& p : posed_points(*o.model, o.T)) model.insert(p);
    const VoxelSet surface = model.dilated();
    std::vector<int> out;
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      if (surface.contains(c.points[i])) out.push_back(c.pixels[i]);
    }
    return out;
  }

  // What GetObjects shows of a foreground object, from its model where it stands now.
  void refresh_info(TouchedObject& o, double stamp_s) {
    const auto pts = posed_points(*o.model, o.T);
    const Aabb box = bounds(pts);
    ObjectCluster& c = o.info.cluster;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& p : pts) sum += p;
    c.centroid = pts.empty() ? o.T.translation() : Eigen::Vector3d(sum / pts.size());
    c.box.center = box.center();
    c.box.rotation = Eigen::Quaterniond::Identity();
    c.box.extents = box.max - box.min;
    c.point_count = o.pixels.size();
    if (o.visible) o.info.last_seen_s = stamp_s;
    if (!o.info.foreground) o.info.foreground = ForegroundState{};
    ForegroundState& s = *o.info.foreground;
    s.T_world_object = o.T;
    s.free = o.free;
    s.handlings = o.handlings;
    if (o.handling) s.handlings.push_back(o.handling->handling(0.0, config.dof));
    s.in_hand = o.in_hand;
    s.visible = o.visible;
    s.model_points = o.model->size();
  }

  // Lost foreground objects first: their clusters are theirs, not new background objects.
  void find_lost(const FrameView& f, const std::vector<ObjectCluster>& clusters, const HandContact& hands,
                 std::vector<bool>& claimed, ForegroundUpdate& out) {
    for (auto& o : objects) {
      if (!o.promoted || o.visible) continue;
      if (o.lost_in_hand && hands.any()) reseed_in_hand(o, f, clusters, hands, config, claimed, out);
      if (!o.visible) reacquire(o, f, clusters, config, claimed, out);
    }
  }

  // New candidates: background objects a hand touches.
  void add_touched(const FrameView& f, const std::vector<ObjectCluster>& clusters, const std::vector<TrackedObject>& known,
                   const HandContact& hands, const std::vector<bool>& claimed, ObjectSurfaces& surfaces) {
    for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
      const ObjectCluster& c = clusters[ci];
      if (claimed[ci] || c.box.extents.maxCoeff() > kMaxObjectExtentM || !hands.may_touch(c)) continue;
      const std::vector<Eigen::Vector3d> pts = world_points(f, c);
      if (!hands.touches(pts)) continue;
      // A piece of an object already touched (a cup the hand splits in two) is that object.
      bool piece = false;
      for (std::size_t k = 0; k < objects.size() && !piece; ++k) piece = surfaces.mostly_on(k, pts);
      if (piece || mostly_skin(*f.cloud, c.indices)) continue;  // a piece of the hand the detector left out
      const TrackedObject* match = nullptr;
      double best = 0.06;
      for (const auto& k : known) {
        const double d = (k.cluster.centroid - c.centroid).norm();
        if (d < best) best = d, match = &k;
      }
      // Only what stood still in the background for a few frames is a candidate: a cluster that
      // appears in a hand is the hand's, or a foreground object whose track was lost.
      if (!match || match->observations < kMinObservations) continue;
      const auto first = first_seen_at.find(match->id);
      if (first == first_seen_at.end() || (first->second - match->cluster.centroid).norm() > kStillM) continue;
      if (beside_person(*f.hands, c.indices, static_cast<int>(f.cloud->width), static_cast<int>(f.cloud->height))) continue;
      const bool already = std::any_of(objects.begin(), objects.end(), [&](const auto& o) { return o.id == match->id; });
      if (already) continue;
      TouchedObject o;
      o.id = match->id;
      o.info = *match;
      o.info.foreground.reset();
      o.T = o.T_home = object_frame(c, Eigen::Matrix3d::Identity());
      o.model = thinned(cluster_cloud(f, c, o.T.inverse()), config.model_voxel_m, config.max_model_points);
      o.pixels = c.indices;
      o.last_contact = f.frame_index;
      objects.push_back(std::move(o));
    }
  }

  // Where each background object was first seen: a candidate must have stood still.
  void remember_first_seen(const std::vector<TrackedObject>& known) {
    std::map<std::uint64_t, Eigen::Vector3d> seen;
    for (const auto& k : known) {
      const auto it = first_seen_at.find(k.id);
      seen[k.id] = it == first_seen_at.end() ? k.cluster.centroid : it->second;
    }
    first_seen_at.swap(seen);
  }

  // Contacts, handlings, promotion, and the candidates that were touched but never moved. A
  // candidate whose model now lies mostly on a foreground object is a piece of it (a small cluster
  // beside a toy, registered onto the toy as it is carried off): dropped, never promoted.
  void handle_and_promote(const FrameView& f, const HandContact& hands, ObjectSurfaces& surfaces, ForegroundUpdate& out) {
    auto piece_of_foreground = [&](std::size_t k) {
      const auto pts = posed_points(*objects[k].model, objects[k].T);
      for (std::size_t j = 0; j < objects.size(); ++j) {
        if (j == k || !objects[j].promoted) continue;
        if (surfaces.mostly_on(j, pts)) return true;
      }
      return false;
    };
    for (std::size_t k = 0; k < objects.size(); ++k) {
      auto& o = objects[k];
      const bool contact = hands.touches(posed_points(*o.model, o.T));
      o.in_hand = contact;
      handle(o, contact, f, T_support, config, out);
      if (o.promoted || !o.visible) continue;
      o.piece = piece_of_foreground(k);
      if (!o.piece) promote_if_due(o, f, config, out);
    }
    objects.erase(std::remove_if(objects.begin(), objects.end(), [&](const TouchedObject& o) {
                    return !o.promoted && (o.piece || f.frame_index - o.last_contact > static_cast<std::uint64_t>(config.touch_timeout_frames));
                  }), objects.end());
  }

  // Where background changes are the foreground's doing (around each object now and where it
  // stood), and the clusters that are (mostly) a foreground object's pixels: not background objects.
  void report(const FrameView& f, const std::vector<ObjectCluster>& clusters, const std::vector<bool>& claimed,
              ForegroundUpdate& out) {
    for (auto& o : objects) {
      if (o.promoted) refresh_info(o, f.stamp_s);
      const Aabb now = bounds(posed_points(*o.model, o.T)).grown(kQuietMarginM);
      out.quiet_boxes.push_back(now);
      out.quiet_boxes.push_back(bounds(posed_points(*o.model, o.T_home)).grown(kQuietMarginM));
    }
    std::unordered_set<int> mine;
    for (const auto& o : objects)
      if (o.promoted) mine.insert(o.pixels.begin(), o.pixels.end());
    for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
      if (claimed[ci] || mine.empty()) continue;
      std::size_t n = 0;
      for (int i : clusters[ci].indices) n += mine.count(i);
      if (2 * n > clusters[ci].indices.size()) out.claimed_clusters.push_back(ci);
    }
  }
};

Status validate(const ForegroundConfig& c) {
  if (auto st = validate(c.hands); !st) return st;
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(c.contact_m) || c.contact_m > 0.5) return invalid_argument("foreground.contact_m: must be in (0, 0.5] m");
  if (!positive(c.promote_translation_m)) return invalid_argument("foreground.promote_translation_m: must be > 0");
  if (!positive(c.promote_lift_m)) return invalid_argument("foreground.promote_lift_m: must be > 0");
  if (!positive(c.promote_rotation_deg)) return invalid_argument("foreground.promote_rotation_deg: must be > 0");
  if (!(c.vacated_fraction > 0 && c.vacated_fraction <= 1)) return invalid_argument("foreground.vacated_fraction: must be in (0, 1]");
  if (!positive(c.dof.translation_m)) return invalid_argument("foreground.dof_translation_m: must be > 0");
  if (!positive(c.dof.rotation_deg)) return invalid_argument("foreground.dof_rotation_deg: must be > 0");
  if (c.release_frames < 1 || c.touch_timeout_frames < 1) return invalid_argument("foreground.release_frames and touch_timeout_frames: must be >= 1");
  if (!positive(c.search_radius_m) || c.search_radius_m > 2) return invalid_argument("foreground.search_radius_m: must be in (0, 2] m");
  if (!positive(c.mask_m) || !positive(c.model_voxel_m) || !positive(c.target_voxel_m)) return invalid_argument("foreground.mask_m, model_voxel_m, target_voxel_m: must be > 0");
  if (!positive(c.grow_max_rmse_m)) return invalid_argument("foreground.grow_max_rmse_m: must be > 0");
  if (!(c.grow_min_inlier_fraction >= 0 && c.grow_min_inlier_fraction <= 1)) return invalid_argument("foreground.grow_min_inlier_fraction: must be in [0, 1]");
  if (c.max_model_points < 50) return invalid_argument("foreground.max_model_points: must be >= 50");
  return {};
}

ForegroundTracker::ForegroundTracker(ForegroundConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}
ForegroundTracker::~ForegroundTracker() = default;
ForegroundTracker::ForegroundTracker(ForegroundTracker&&) noexcept = default;
ForegroundTracker& ForegroundTracker::operator=(ForegroundTracker&&) noexcept = default;

std::vector<int> ForegroundTracker::track(const FrameView& f) {
  Impl& m = *impl_;
  m.T_support = support_frame(f.up_world);
  std::vector<int> pixels;
  for (auto& o : m.objects) {
    Pose guess = o.T;
    guess.translation() += o.velocity;
    Crop c;
    const Registration r = m.locate(o, f, guess, c);
    o.pixels.clear();
    if (!r.ok) {
      if (o.visible) o.lost_in_hand = o.in_hand;
      o.visible = false;
      o.velocity.setZero();
      continue;
    }
    const Eigen::Vector3d step = r.T_world_object.translation() - o.T.translation();
    o.velocity = step.norm() < m.config.search_radius_m / 2 ? step : Eigen::Vector3d::Zero();
    o.T = r.T_world_object;
    o.visible = true;
    o.lost_in_hand = false;
    o.pixels = m.pixels_on(o, c);
    if (!o.promoted) continue;
    pixels.insert(pixels.end(), o.pixels.begin(), o.pixels.end());
    if (m.config.grow_model && worth_merging(r, m.growth))
      o.model = merged(o.model, *f.cloud, o.pixels, o.T.inverse() * f.T_world_camera, m.growth);
  }
  return pixels;
}

ForegroundUpdate ForegroundTracker::update(const FrameView& f, const std::vector<ObjectCluster>& clusters,
                                           const std::vector<TrackedObject>& known) {
  Impl& m = *impl_;
  ForegroundUpdate out;
  std::vector<bool> claimed(clusters.size(), false);
  const HandContact hands(f, m.config.contact_m);
  m.find_lost(f, clusters, hands, claimed, out);
  ObjectSurfaces surfaces(m.objects, m.config.mask_m * 2);
  if (hands.any()) m.add_touched(f, clusters, known, hands, claimed, surfaces);
  m.remember_first_seen(known);
  m.handle_and_promote(f, hands, surfaces, out);
  m.report(f, clusters, claimed, out);
  return out;
}

std::vector<TrackedObject> ForegroundTracker::objects() const {
  std::vector<TrackedObject> out;
  for (const auto& o : impl_->objects)
    if (o.promoted) out.push_back(o.info);
  return out;
}

std::vector<std::uint64_t> ForegroundTracker::candidates() const {
  std::vector<std::uint64_t> out;
  for (const auto& o : impl_->objects)
    if (!o.promoted) out.push_back(o.id);
  return out;
}

CloudConstPtr ForegroundTracker::model(std::uint64_t id) const {
  for (const auto& o : impl_->objects)
    if (o.id == id) return o.model;
  return nullptr;
}

void ForegroundTracker::restore(const TrackedObject& object, CloudConstPtr model) {
  TouchedObject o;
  o.id = object.id;
  o.promoted = true;
  o.model = std::make_shared<Cloud>(*model);
  o.info = object;
  if (object.foreground) {
    o.T = object.foreground->T_world_object;
    o.free = object.foreground->free;
    for (const auto& h : object.foreground->handlings)
      if (h.end_s > 0) o.handlings.push_back(h);
  }
  o.T_home = o.T;
  o.visible = false;
  impl_->objects.push_back(std::move(o));
}

void ForegroundTracker::reset() {
  impl_->objects.clear();
  impl_->first_seen_at.clear();
}

}  // namespace scenewatch::foreground
