// Promotion (promotion.h): how far a candidate went from where it stood, whether its old place
// is seen empty, and the OBJECT_PROMOTED event.
#include "promotion.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "frame_crop.h"
#include "object_points.h"
#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
constexpr double kSeenThroughM = 0.02;     // a pixel this much deeper than a point sees through it
constexpr double kLiftedVacatedFraction = 0.1;     // of its old place a lifted object must have emptied

double rotation_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * kDegPerRad;
}

// The share of the model, placed where it stood, that the frame still sees filled: of the
// points the frame observes (neither hidden behind something nearer nor without depth), those
// whose pixel holds a surface at their depth; the others are seen through, hence empty.
double still_filled(const TouchedObject& o, const FrameView& f, const ForegroundConfig& config) {
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

// How far a candidate went from where it stood.
struct Departure {
  double moved_m = 0, turned_deg = 0, lifted_m = 0, sideways_m = 0;
};

Departure departure(const TouchedObject& o, const FrameView& f) {
  const Eigen::Vector3d d = o.T.translation() - o.T_home.translation();
  const Eigen::Vector3d up = f.up_world.normalized();
  Departure out;
  out.moved_m = d.norm();
  out.turned_deg = rotation_deg(o.T, o.T_home);
  out.lifted_m = d.dot(up);
  out.sideways_m = (d - out.lifted_m * up).norm();
  return out;
}

void promote(TouchedObject& o, const FrameView& f, const Departure& d, const std::string& why, const ForegroundConfig& config,
             ForegroundUpdate& out) {
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

}  // namespace

void promote_if_due(TouchedObject& o, const FrameView& f, const ForegroundConfig& config, ForegroundUpdate& out) {
  const Departure d = departure(o, f);
  if (d.lifted_m > config.promote_lift_m && d.lifted_m > d.sideways_m) {
    promote(o, f, d, "lifted off its support", config, out);
    return;
  }
  if (d.moved_m <= config.promote_translation_m && d.turned_deg <= config.promote_rotation_deg) return;
  // Lifted off its support, the object empties only the band under it (a cylinder's side wall
  // stays where it was): then that band is evidence enough.
  const bool lifted = d.lifted_m > config.promote_translation_m;
  const double filled = still_filled(o, f, config);
  if (filled > 1.0 - (lifted ? kLiftedVacatedFraction : config.vacated_fraction)) return;
  std::ostringstream why;
  why.precision(3);
  why << "its old place is " << 100 * (1 - filled) << " % empty";
  promote(o, f, d, why.str(), config, out);
}

}  // namespace scenewatch::foreground
