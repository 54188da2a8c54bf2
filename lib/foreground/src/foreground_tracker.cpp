// Touched objects, their promotion to the foreground, their tracking and their handlings.
#include "scenewatch/foreground/foreground_tracker.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <unordered_set>

#include "point_model.h"
#include "skin_model.h"
#include "voxel_set.h"

namespace scenewatch::foreground {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
constexpr double kQuietMarginM = 0.05;    // background changes this close to a foreground object are its doing
constexpr double kSupportBandM = 0.012;   // frame points this close to a supporting plane are the plane's
constexpr double kMaxObjectExtentM = 0.6;  // a touched cluster larger than this is furniture, not an object
constexpr double kSeenThroughM = 0.02;     // a pixel this much deeper than a point sees through it
constexpr int kMinObservations = 3;        // frames a background object was seen before it can be a candidate
constexpr double kStillM = 0.03;           // a candidate moved at most this far since it was first seen
constexpr double kSearchMarginM = 0.08;    // registration targets reach this far beyond the model
constexpr std::size_t kRegistrationPoints = 300;  // model points registration uses
constexpr double kBoxSlackM = 0.02;       // a cluster's points lie this close to its box at most
constexpr double kLiftedVacatedFraction = 0.1;     // of its old place a lifted object must have emptied

Eigen::Vector3d world(const PointT& p, const Pose& T) { return T * p.getVector3fMap().cast<double>(); }

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

double rotation_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * kDegPerRad;
}

Aabb bounds(const std::vector<Eigen::Vector3d>& pts) {
  Aabb box{Eigen::Vector3d::Constant(1e30), Eigen::Vector3d::Constant(-1e30)};
  for (const auto& p : pts) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  return box;
}

// Keeps one point per voxel (the first), at most `max_points`.
CloudPtr thinned(const Cloud& in, double voxel, std::size_t max_points) {
  auto out = std::make_shared<Cloud>();
  if (voxel > 0) {
    VoxelSet seen(voxel);
    for (const auto& p : in.points) {
      if (seen.insert(p.getVector3fMap().cast<double>())) out->push_back(p);
    }
  } else {
    *out = in;
  }
  if (out->size() > max_points) {
    auto every = std::make_shared<Cloud>();
    const double step = static_cast<double>(out->size()) / max_points;
    for (double i = 0; i < out->size() && every->size() < max_points; i += step) every->push_back(out->points[static_cast<std::size_t>(i)]);
    out = every;
  }
  out->width = static_cast<std::uint32_t>(out->size());
  out->height = 1;
  return out;
}

// The world box around a cluster's oriented box (clusters come in the world frame).
Aabb world_box(const ObjectCluster& c) {
  const Eigen::Matrix3d R = c.box.rotation.toRotationMatrix();
  const Eigen::Vector3d half = (R.cwiseAbs() * c.box.extents) / 2;
  return {c.box.center - half, c.box.center + half};
}

// A cluster's points (world frame).
std::vector<Eigen::Vector3d> world_points(const FrameView& f, const ObjectCluster& c) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(c.indices.size());
  for (int i : c.indices) out.push_back(world(f.cloud->points[static_cast<std::size_t>(i)], f.T_world_camera));
  return out;
}

// A cluster's points with their colour, in the frame T_frame_world maps the world into (the world
// itself for a registration target, an object's frame for its model).
Cloud cluster_cloud(const FrameView& f, const ObjectCluster& c, const Pose& T_frame_world) {
  const Pose T = T_frame_world * f.T_world_camera;
  Cloud out;
  for (int i : c.indices) {
    PointT q = f.cloud->points[static_cast<std::size_t>(i)];
    q.getVector3fMap() = (T * q.getVector3fMap().cast<double>()).cast<float>();
    out.push_back(q);
  }
  out.width = static_cast<std::uint32_t>(out.size());
  out.height = 1;
  return out;
}

// The frame of an object seen as cluster c, turned as R: origin at the cluster's centroid.
Pose object_frame(const ObjectCluster& c, const Eigen::Matrix3d& R) {
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = c.centroid;
  return T;
}

std::vector<Eigen::Vector3d> posed_points(const Cloud& model, const Pose& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(model.size());
  for (const auto& p : model.points) out.push_back(world(p, T));
  return out;
}

// The frame's points near a centre: thinned (registration target) and all of them (pixel index
// and world position), without agents and without the supporting planes' surfaces.
struct Crop {
  Cloud target;
  std::vector<int> pixels;
  std::vector<Eigen::Vector3d> points;
};

// The pixels whose points can lie within `radius` of `centre` (camera frame): the image box of
// the sphere's bounding box; the whole image when the camera is unknown or inside the sphere.
struct PixelWindow {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;  // [u0, u1) x [v0, v1)
};

PixelWindow pixel_window(const FrameView& f, const Eigen::Vector3f& centre, double radius) {
  const Cloud& cloud = *f.cloud;
  PixelWindow w{0, 0, static_cast<int>(cloud.width), static_cast<int>(cloud.height)};
  const double near = centre.z() - radius, far = centre.z() + radius;
  if (!f.K || cloud.height <= 1 || near <= 0.01) return w;
  auto span = [&](double c, double focal, double principal, int size, int& lo, int& hi) {
    const double a = (c - radius) / near, b = (c - radius) / far, d = (c + radius) / near, e = (c + radius) / far;
    lo = std::max(0, static_cast<int>(std::floor(principal + focal * std::min({a, b, d, e}))) - 1);
    hi = std::min(size, static_cast<int>(std::ceil(principal + focal * std::max({a, b, d, e}))) + 2);
  };
  span(centre.x(), f.K->fx, f.K->cx, w.u1, w.u0, w.u1);
  span(centre.y(), f.K->fy, f.K->cy, w.v1, w.v0, w.v1);
  return w;
}

// Adds pixel i to the crop when its point lies within the sphere and is neither an agent's nor
// on a supporting plane.
void add_to_crop(const FrameView& f, std::size_t i, const Eigen::Vector3f& centre_cam, float r2,
                 const std::vector<const Plane*>& supports, VoxelSet& kept, Crop& c) {
  const PointT& p = f.cloud->points[i];
  if (!is_valid(p) || (p.getVector3fMap() - centre_cam).squaredNorm() > r2) return;
  if (f.hands && f.hands->is_agent(static_cast<int>(i))) return;
  const Eigen::Vector3d w = world(p, f.T_world_camera);
  for (const Plane* pl : supports)
    if (std::abs(pl->signed_distance(w)) < kSupportBandM) return;
  c.pixels.push_back(static_cast<int>(i));
  c.points.push_back(w);
  if (!kept.insert(w)) return;
  PointT q = p;
  q.getVector3fMap() = w.cast<float>();
  c.target.push_back(q);
}

Crop crop(const FrameView& f, const Eigen::Vector3d& centre_world, double radius, double voxel) {
  Crop c;
  const Pose& T = f.T_world_camera;
  const Eigen::Vector3f centre_cam = (T.inverse() * centre_world).cast<float>();
  const float r2 = static_cast<float>(radius * radius);
  std::vector<const Plane*> supports;
  if (f.planes) {
    for (const auto& pl : *f.planes) {
      if (pl.normal.dot(f.up_world) > 0.9) supports.push_back(&pl);
    }
  }
  VoxelSet kept(voxel);
  const Cloud& cloud = *f.cloud;
  const PixelWindow w = pixel_window(f, centre_cam, radius);
  const std::size_t area = static_cast<std::size_t>(std::max(0, w.u1 - w.u0)) * static_cast<std::size_t>(std::max(0, w.v1 - w.v0));
  c.pixels.reserve(area / 2);
  c.points.reserve(area / 2);
  for (int v = w.v0; v < w.v1; ++v)
    for (int u = w.u0; u < w.u1; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * cloud.width + static_cast<std::size_t>(u);
      add_to_crop(f, i, centre_cam, r2, supports, kept, c);
    }
  c.target.width = static_cast<std::uint32_t>(c.target.size());
  c.target.height = 1;
  return c;
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

// True when most of the cluster's pixels have skin colour.
bool mostly_skin(const Cloud& cloud, const std::vector<int>& indices) {
  if (indices.empty()) return false;
  const auto skin = skin_mask(cloud, indices);
  std::size_t n = 0;
  for (auto v : skin) n += v ? 1 : 0;
  return 2 * n > indices.size();
}

}  // namespace

struct ForegroundTracker::Impl {
  explicit Impl(ForegroundConfig c) : config(std::move(c)) {
    growth.voxel_m = config.model_voxel_m;
    growth.max_points = config.max_model_points;
    growth.max_rmse_m = config.grow_max_rmse_m;
    growth.min_inlier_fraction = config.grow_min_inlier_fraction;
  }

  struct Object {
    std::uint64_t id = 0;
    bool promoted = false;
    CloudPtr model;                       // object frame, with colour
    Pose T = Pose::Identity();            // T_world_object now
    Pose T_home = Pose::Identity();       // where it stood when first touched
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // per frame
    bool visible = true;
    bool in_hand = false;
    bool lost_in_hand = false;            // its track was lost while a hand held it
    bool piece = false;                   // a candidate found to be a piece of a foreground object
    CloudPtr sparse;                      // the model thinned for registration
    const Cloud* sparse_of = nullptr;     // the model it was thinned from
    std::vector<int> pixels;              // this frame
    std::optional<HandlingRecorder> handling;
    bool handling_raised = false;
    std::uint64_t last_contact = 0;
    std::vector<Handling> handlings;
    DofFlags free{};
    TrackedObject info;                   // what GetObjects shows
  };

  ForegroundConfig config;
  ModelGrowth growth;
  std::vector<Object> objects;  // candidates and foreground objects, in the order first touched
  std::map<std::uint64_t, Eigen::Vector3d> first_seen_at;  // background objects: where they were first seen
  Pose T_support = Pose::Identity();

  // The object in this frame: registration targets within its own size (plus a margin for a
  // fast motion) of where it is predicted, the model thinned to what registration needs.
  Registration locate(Object& o, const FrameView& f, const Pose& guess, Crop& c) {
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
  std::vector<int> pixels_on(const Object& o, const Crop& c) const {
    VoxelSet model(config.mask_m);
    for (const auto& p : posed_points(*o.model, o.T)) model.insert(p);
    const VoxelSet surface = model.dilated();
    std::vector<int> out;
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      if (surface.contains(c.points[i])) out.push_back(c.pixels[i]);
    }
    return out;
  }

  // The share of the model, placed where it stood, that the frame still sees filled: of the
  // points the frame observes (neither hidden behind something nearer nor without depth), those
  // whose pixel holds a surface at their depth; the others are seen through, hence empty.
  double still_filled(const Object& o, const FrameView& f) const {
    const auto home = posed_points(*o.model, o.T_home);
    if (home.empty()) return 1.0;
    if (!f.K || f.cloud->height <= 1) {
      const Crop c = crop(f, o.T_home.translation(), config.search_radius_m, config.target_voxel_m);
      VoxelSet frame(config.registration.inlier_m * 1.5);
      for (const auto& p : c.points) frame.insert(p);
      std::size_t filled = 0;
      for (const auto& p : home) filled += frame.near(p) ? 1 : 0;
      return static_cast<double>(filled) / home.size();
    }
    const Pose T_cw = f.T_world_camera.inverse();
    const Cloud& cloud = *f.cloud;
    std::size_t filled = 0, empty = 0;
    for (const auto& pw : home) {
      const Eigen::Vector3d p = T_cw * pw;
      if (p.z() <= 0) continue;
      const int u = static_cast<int>(std::lround(f.K->fx * p.x() / p.z() + f.K->cx));
      const int v = static_cast<int>(std::lround(f.K->fy * p.y() / p.z() + f.K->cy));
      if (u < 0 || v < 0 || u >= static_cast<int>(cloud.width) || v >= static_cast<int>(cloud.height)) continue;
      const int i = v * static_cast<int>(cloud.width) + u;
      const PointT& q = cloud.points[static_cast<std::size_t>(i)];
      if (!is_valid(q) || (f.hands && f.hands->is_agent(i))) continue;
      const double depth = q.z;
      if (depth > p.z() + kSeenThroughM) ++empty;
      else if (depth > p.z() - kSeenThroughM) ++filled;
      // nearer: hidden behind something, unknown
    }
    const std::size_t observed = filled + empty;
    if (observed < std::max<std::size_t>(10, home.size() / 10)) return 1.0;  // too little of it seen to tell
    return static_cast<double>(filled) / observed;
  }

  void refresh_info(Object& o, double stamp_s) {
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

  Event event_for(const Object& o, EventKind kind, EventLevel level, const FrameView& f) const {
    Event e;
    e.kind = kind;
    e.level = level;
    e.stamp_s = f.stamp_s;
    e.object_id = o.id;
    const auto pts = posed_points(*o.model, o.T);
    e.box_world = bounds(pts);
    e.centroid_world = e.box_world.center();
    e.evidence["frame"] = static_cast<double>(f.frame_index);
    return e;
  }

  // The handling of one object in this frame: start, record, raise, end.
  void handle(Object& o, bool contact, const FrameView& f, ForegroundUpdate& out) {
    if (contact) {
      o.last_contact = f.frame_index;
      if (!o.handling) {
        o.handling.emplace(T_support, o.T, f.stamp_s);
        o.handling_raised = false;
      }
    }
    if (!o.handling) return;
    if (o.visible) {
      const DofFlags fresh = o.handling->add(o.T, config.dof);
      const bool learning = o.handlings.empty();
      if (o.promoted && !learning && !o.handling_raised) raise_frozen(o, fresh, f, out);
    }
    if (f.frame_index - o.last_contact > static_cast<std::uint64_t>(config.release_frames)) {
      const Handling h = o.handling->handling(f.stamp_s, config.dof);
      if (o.promoted) {
        for (std::size_t k = 0; k < h.moved.size(); ++k) o.free[k] = o.free[k] || h.moved[k];
        o.handlings.push_back(h);
      }
      o.handling.reset();
    }
  }

  void raise_frozen(Object& o, const DofFlags& fresh, const FrameView& f, ForegroundUpdate& out) {
    const Handling now = o.handling->handling(0.0, config.dof);
    int worst = -1;
    double worst_ratio = 0;
    std::string named;
    for (int k = 0; k < kDofCount; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      if (!fresh[ks] || o.free[ks]) continue;
      const double ratio = now.range[ks] / (k < 3 ? config.dof.translation_m : config.dof.rotation_deg);
      named += (named.empty() ? "" : ", ") + std::string(to_string(static_cast<Dof>(k)));
      if (ratio > worst_ratio) worst_ratio = ratio, worst = k;
    }
    if (worst < 0) return;
    Event e = event_for(o, EventKind::kFrozenDofMotion, EventLevel::kImplausibility, f);
    const auto ws = static_cast<std::size_t>(worst);
    e.score = worst_ratio;
    std::ostringstream detail;
    detail.precision(3);
    detail << "motion in frozen DoF " << to_string(static_cast<Dof>(worst)) << ": " << now.range[ws]
           << (worst < 3 ? " m" : " deg") << " (frozen DoFs that moved: " << named << ")";
    e.detail = detail.str();
    e.evidence["dof"] = worst;
    e.evidence["magnitude"] = now.range[ws];
    e.evidence["handling"] = static_cast<double>(o.handlings.size());
    for (int k = 0; k < kDofCount; ++k) e.evidence[std::string("range_") + to_string(static_cast<Dof>(k))] = now.range[static_cast<std::size_t>(k)];
    out.events.push_back(std::move(e));
    o.handling_raised = true;
  }

  // How far a candidate went from where it stood.
  struct Departure {
    double moved_m = 0, turned_deg = 0, lifted_m = 0, sideways_m = 0;
  };

  Departure departure(const Object& o, const FrameView& f) const {
    const Eigen::Vector3d d = o.T.translation() - o.T_home.translation();
    const Eigen::Vector3d up = f.up_world.normalized();
    Departure out;
    out.moved_m = d.norm();
    out.turned_deg = rotation_deg(o.T, o.T_home);
    out.lifted_m = d.dot(up);
    out.sideways_m = (d - out.lifted_m * up).norm();
    return out;
  }

  // A touched object (a candidate: a hand touched it within touch_timeout_frames) is promoted
  // once it left its place: lifted off its support (a pick starts along the support's normal,
  // and while a cup's side wall still hides its old place none of that place is seen empty yet;
  // no contact is asked in this frame, as the hand that grasps a cup is often hidden behind it),
  // or moved or turned beyond the promotion thresholds with its old place seen empty.
  void promote_if_due(Object& o, const FrameView& f, ForegroundUpdate& out) {
    const Departure d = departure(o, f);
    if (d.lifted_m > config.promote_lift_m && d.lifted_m > d.sideways_m) {
      promote(o, f, d, "lifted off its support", out);
      return;
    }
    if (d.moved_m <= config.promote_translation_m && d.turned_deg <= config.promote_rotation_deg) return;
    // Lifted off its support, the object empties only the band under it (a cylinder's side wall
    // stays where it was): then that band is evidence enough.
    const bool lifted = d.lifted_m > config.promote_translation_m;
    const double filled = still_filled(o, f);
    if (filled > 1.0 - (lifted ? kLiftedVacatedFraction : config.vacated_fraction)) return;
    std::ostringstream why;
    why.precision(3);
    why << "its old place is " << 100 * (1 - filled) << " % empty";
    promote(o, f, d, why.str(), out);
  }

  void promote(Object& o, const FrameView& f, const Departure& d, const std::string& why, ForegroundUpdate& out) {
    o.promoted = true;
    o.info.foreground = ForegroundState{};
    o.info.foreground->promoted_s = f.stamp_s;
    Event e = event_for(o, EventKind::kObjectPromoted, EventLevel::kPrediction, f);
    e.score = std::max({d.moved_m / config.promote_translation_m, d.turned_deg / config.promote_rotation_deg,
                        d.lifted_m / config.promote_lift_m});
    std::ostringstream detail;
    detail.precision(3);
    detail << "touched by a hand and moved " << d.moved_m << " m (lifted " << d.lifted_m << " m), turned "
           << d.turned_deg << " deg; " << why;
    e.detail = detail.str();
    e.evidence["moved_m"] = d.moved_m;
    e.evidence["lifted_m"] = d.lifted_m;
    e.evidence["turned_deg"] = d.turned_deg;
    e.evidence["model_points"] = static_cast<double>(o.model->size());
    e.displacement_world = o.T.translation() - o.T_home.translation();
    out.events.push_back(std::move(e));
    out.vacated.push_back(posed_points(*o.model, o.T_home));
    out.promoted.push_back(o.id);
  }

  // A lost foreground object among the frame's clusters near its last place.
  void reacquire(Object& o, const FrameView& f, const std::vector<ObjectCluster>& clusters,
                 std::vector<bool>& claimed, ForegroundUpdate& out) {
    const Aabb model_box = bounds(posed_points(*o.model, Pose::Identity()));
    const double model_size = (model_box.max - model_box.min).norm();
    Registration best;
    std::size_t best_cluster = clusters.size();
    for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
      const ObjectCluster& c = clusters[ci];
      if (claimed[ci] || (c.centroid - o.T.translation()).norm() > config.reacquire_radius_m) continue;
      if (c.box.extents.norm() > 2.5 * model_size) continue;
      const Cloud target = *thinned(cluster_cloud(f, c, Pose::Identity()), config.target_voxel_m, 20000);
      for (int turn = 0; turn < 4; ++turn) {
        Pose guess = o.T;
        guess.linear() = Eigen::AngleAxisd(turn * M_PI / 2, f.up_world).toRotationMatrix() * o.T.linear();
        guess.translation() = c.centroid;
        const Registration r = register_model(*o.model, target, guess, f.T_world_camera.translation(), config.registration, f.up_world);
        if (r.ok && r.inlier_fraction > best.inlier_fraction) best = r, best_cluster = ci;
      }
    }
    if (best_cluster == clusters.size()) return;
    o.T = best.T_world_object;
    o.visible = true;
    o.velocity.setZero();
    claimed[best_cluster] = true;
    out.claimed_clusters.push_back(best_cluster);
    o.pixels = clusters[best_cluster].indices;
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
  const ForegroundConfig& cfg = m.config;
  ForegroundUpdate out;
  std::vector<bool> claimed(clusters.size(), false);

  // Where the hands are: the hand proper (the forearm touches nothing it carries).
  VoxelSet hand_points(cfg.contact_m);
  bool any_hand = false;
  Aabb hand_box{Eigen::Vector3d::Constant(1e30), Eigen::Vector3d::Constant(-1e30)};
  if (f.hands) {
    for (const auto& h : f.hands->hands) {
      for (int i : h.tip_indices.empty() ? h.indices : h.tip_indices) {
        const PointT& p = f.cloud->points[static_cast<std::size_t>(i)];
        if (!is_valid(p)) continue;
        const Eigen::Vector3d w = world(p, f.T_world_camera);
        hand_points.insert(w);
        hand_box.min = hand_box.min.cwiseMin(w);
        hand_box.max = hand_box.max.cwiseMax(w);
        any_hand = true;
      }
    }
  }
  const VoxelSet hand = hand_points.dilated();
  // Where a touch can be at all: a point in a cell next to a hand point's is at most two cells
  // from it. A cluster whose box lies farther needs none of its points looked at (the box of a
  // cluster segmented on every second pixel is its samples': its other pixels lie within one
  // segmentation voxel of them, hence kBoxSlackM).
  const Aabb reach = hand_box.grown(2 * cfg.contact_m + kBoxSlackM);
  auto may_touch = [&](const ObjectCluster& c) { return any_hand && reach.overlaps(world_box(c)); };
  auto touches = [&](const std::vector<Eigen::Vector3d>& pts) {
    if (!any_hand) return false;
    for (const auto& p : pts)
      if (hand.contains(p)) return true;
    return false;
  };

  // Lost foreground objects first: their clusters are theirs, not new background objects. What a
  // hand holds when the track of the object it held was lost is that object (a plush toy deforms
  // and turns faster than registration follows at 10 frames per second): its model is re-seeded.
  for (auto& o : m.objects) {
    if (!o.promoted || o.visible) continue;
    if (o.lost_in_hand && any_hand) {
      for (std::size_t ci = 0; ci < clusters.size() && !o.visible; ++ci) {
        const ObjectCluster& c = clusters[ci];
        if (claimed[ci] || c.box.extents.maxCoeff() > kMaxObjectExtentM || !may_touch(c) || mostly_skin(*f.cloud, c.indices)) continue;
        if (!touches(world_points(f, c))) continue;
        o.T = object_frame(c, o.T.linear());
        o.model = thinned(cluster_cloud(f, c, o.T.inverse()), cfg.model_voxel_m, cfg.max_model_points);
        o.visible = true;
        o.lost_in_hand = false;
        o.velocity.setZero();
        o.pixels = c.indices;
        claimed[ci] = true;
        out.claimed_clusters.push_back(ci);
      }
    }
    if (!o.visible) m.reacquire(o, f, clusters, claimed, out);
  }

  // New candidates: background objects a hand touches. Each touched object's surface (grown by
  // one voxel, for one lookup per point) is made once, when a cluster is first tested against it.
  std::vector<std::optional<VoxelSet>> surfaces;
  auto surface_of = [&](std::size_t k) -> const VoxelSet& {
    if (surfaces.size() <= k) surfaces.resize(m.objects.size());
    if (!surfaces[k]) {
      VoxelSet points(cfg.mask_m * 2);
      for (const auto& p : posed_points(*m.objects[k].model, m.objects[k].T)) points.insert(p);
      surfaces[k] = points.dilated();
    }
    return *surfaces[k];
  };
  if (any_hand) {
    for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
      const ObjectCluster& c = clusters[ci];
      if (claimed[ci] || c.box.extents.maxCoeff() > kMaxObjectExtentM || !may_touch(c)) continue;
      const std::vector<Eigen::Vector3d> pts = world_points(f, c);
      if (!touches(pts)) continue;
      // A piece of an object already touched (a cup the hand splits in two) is that object.
      bool piece = false;
      for (std::size_t k = 0; k < m.objects.size() && !piece; ++k) {
        const VoxelSet& surface = surface_of(k);
        std::size_t near = 0;
        for (const auto& p : pts) near += surface.contains(p) ? 1 : 0;
        piece = 2 * near > pts.size();
      }
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
      const auto first = m.first_seen_at.find(match->id);
      if (first == m.first_seen_at.end() || (first->second - match->cluster.centroid).norm() > kStillM) continue;
      if (beside_person(*f.hands, c.indices, static_cast<int>(f.cloud->width), static_cast<int>(f.cloud->height))) continue;
      const bool already = std::any_of(m.objects.begin(), m.objects.end(), [&](const auto& o) { return o.id == match->id; });
      if (already) continue;
      Impl::Object o;
      o.id = match->id;
      o.info = *match;
      o.info.foreground.reset();
      o.T = o.T_home = object_frame(c, Eigen::Matrix3d::Identity());
      o.model = thinned(cluster_cloud(f, c, o.T.inverse()), cfg.model_voxel_m, cfg.max_model_points);
      o.pixels = c.indices;
      o.last_contact = f.frame_index;
      m.objects.push_back(std::move(o));
    }
  }

  // Where each background object was first seen: a candidate must have stood still.
  std::map<std::uint64_t, Eigen::Vector3d> seen;
  for (const auto& k : known) {
    const auto it = m.first_seen_at.find(k.id);
    seen[k.id] = it == m.first_seen_at.end() ? k.cluster.centroid : it->second;
  }
  m.first_seen_at.swap(seen);

  // Contacts, handlings, promotion, and the candidates that were touched but never moved. A
  // candidate whose model now lies mostly on a foreground object is a piece of it (a small cluster
  // beside a toy, registered onto the toy as it is carried off): dropped, never promoted.
  auto piece_of_foreground = [&](std::size_t k) {
    const auto pts = posed_points(*m.objects[k].model, m.objects[k].T);
    for (std::size_t j = 0; j < m.objects.size(); ++j) {
      if (j == k || !m.objects[j].promoted) continue;
      const VoxelSet& surface = surface_of(j);
      std::size_t near = 0;
      for (const auto& p : pts) near += surface.contains(p) ? 1 : 0;
      if (2 * near > pts.size()) return true;
    }
    return false;
  };
  for (std::size_t k = 0; k < m.objects.size(); ++k) {
    auto& o = m.objects[k];
    const bool contact = touches(posed_points(*o.model, o.T));
    o.in_hand = contact;
    m.handle(o, contact, f, out);
    if (o.promoted || !o.visible) continue;
    o.piece = piece_of_foreground(k);
    if (!o.piece) m.promote_if_due(o, f, out);
  }
  m.objects.erase(std::remove_if(m.objects.begin(), m.objects.end(), [&](const Impl::Object& o) {
                    return !o.promoted && (o.piece || f.frame_index - o.last_contact > static_cast<std::uint64_t>(cfg.touch_timeout_frames));
                  }), m.objects.end());

  for (auto& o : m.objects) {
    if (o.promoted) m.refresh_info(o, f.stamp_s);
    const Aabb now = bounds(posed_points(*o.model, o.T)).grown(kQuietMarginM);
    out.quiet_boxes.push_back(now);
    out.quiet_boxes.push_back(bounds(posed_points(*o.model, o.T_home)).grown(kQuietMarginM));
  }
  // Clusters that are (mostly) a foreground object's pixels are not background objects.
  std::unordered_set<int> mine;
  for (const auto& o : m.objects)
    if (o.promoted) mine.insert(o.pixels.begin(), o.pixels.end());
  for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
    if (claimed[ci] || mine.empty()) continue;
    std::size_t n = 0;
    for (int i : clusters[ci].indices) n += mine.count(i);
    if (2 * n > clusters[ci].indices.size()) out.claimed_clusters.push_back(ci);
  }
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
  Impl::Object o;
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
