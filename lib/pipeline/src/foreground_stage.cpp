#include "foreground_stage.h"

#include <cmath>
#include <limits>

#include "timing.h"

namespace scenewatch::pipeline {

bool faces_within_45_degrees(const Plane& plane, const Eigen::Vector3d& camera, const Eigen::Vector3d& direction) {
  return plane.normal_towards(camera).dot(direction) >= std::cos(M_PI / 4);
}

std::optional<Eigen::Vector3d> level_up(const std::optional<Eigen::Vector3d>& configured, const std::vector<Plane>& planes,
                                        const Pose& T_world_camera) {
  if (configured && configured->norm() > 0) return configured->normalized();
  const Eigen::Vector3d camera = T_world_camera.translation();
  const Eigen::Vector3d camera_up = -T_world_camera.linear().col(1);
  const Plane* upright = nullptr;
  for (const auto& p : planes) {
    if (faces_within_45_degrees(p, camera, camera_up) && (!upright || p.area_m2 > upright->area_m2)) upright = &p;
  }
  if (upright) return upright->normal_towards(camera);
  return std::nullopt;
}

Eigen::Vector3d up_direction(const std::optional<Eigen::Vector3d>& configured, const std::vector<Plane>& planes,
                             const Pose& T_world_camera) {
  if (const auto up = level_up(configured, planes, T_world_camera)) return *up;
  const Plane* largest = nullptr;
  for (const auto& p : planes)
    if (!largest || p.area_m2 > largest->area_m2) largest = &p;
  return largest ? largest->normal_towards(T_world_camera.translation()) : Eigen::Vector3d::UnitZ();
}

namespace {

HandsSeen summarise(const foreground::HandDetection& d, const Cloud& cloud, const Pose& T, std::uint64_t index, double stamp_s) {
  HandsSeen s;
  s.frame_index = index;
  s.stamp_s = stamp_s;
  auto box_of = [&](const std::vector<int>& pixels) {
    Aabb box{Eigen::Vector3d::Constant(1e30), Eigen::Vector3d::Constant(-1e30)};
    for (int i : pixels) {
      const PointT& p = cloud.points[static_cast<std::size_t>(i)];
      if (!is_valid(p)) continue;
      const Eigen::Vector3d w = T * p.getVector3fMap().cast<double>();
      box.min = box.min.cwiseMin(w);
      box.max = box.max.cwiseMax(w);
    }
    return box;
  };
  for (const auto& h : d.hands) {
    HandSeen hs;
    hs.box_world = box_of(h.indices);
    hs.tip_world = T * h.tip_camera;
    hs.score = h.score;
    hs.pixels = h.indices.size();
    hs.enters_from_border = h.enters_from_border;
    if (hs.box_world.valid()) s.hands.push_back(hs);
  }
  s.person_pixels = d.person_indices.size();
  if (!d.person_indices.empty()) {
    const Aabb b = box_of(d.person_indices);
    if (b.valid()) s.person_box_world = b;
  }
  return s;
}

}  // namespace

// A skin-coloured region where the map has remembered a surface for a while is furniture (a wooden
// worktop), not a hand: hands come and go, the background stays. A point is on a remembered
// surface when an occupied voxel lies along its ray within the map tolerance of the sensor model
// (change::map_tolerance_m: sigma_factor times the axial noise at its range), as for change
// evidence. Drops such hands, and the person grown from them when none is left.
void ForegroundStage::drop_static_hands(const Cloud& cloud, const Pose& T, const OccupiedFraction& occupied) {
  if (!occupied || detection_.hands.empty()) return;
  std::vector<foreground::Hand> kept;
  for (auto& h : detection_.hands) {
    std::vector<Eigen::Vector3d> pts;
    const std::size_t step = std::max<std::size_t>(1, h.indices.size() / 200);
    for (std::size_t k = 0; k < h.indices.size(); k += step) {
      const PointT& p = cloud.points[static_cast<std::size_t>(h.indices[k])];
      if (is_valid(p)) pts.push_back(T * p.getVector3fMap().cast<double>());
    }
    if (!pts.empty() && occupied(pts, T.translation()) > kStaticHandFraction) {
      for (int i : h.indices) detection_.labels[static_cast<std::size_t>(i)] = foreground::AgentLabel::kNone;
      continue;
    }
    kept.push_back(std::move(h));
  }
  detection_.hands = std::move(kept);
  if (detection_.hands.empty()) {
    for (int i : detection_.person_indices) detection_.labels[static_cast<std::size_t>(i)] = foreground::AgentLabel::kNone;
    detection_.person_indices.clear();
  }
}

Frame ForegroundStage::prepare(const Frame& frame, std::uint64_t frame_index, const std::vector<Plane>& planes,
                               const std::optional<Eigen::Vector3d>& configured_up, const OccupiedFraction& occupied,
                               FrameResult& result, std::uint32_t camera) {
  const Pose T = frame.pose_or_identity();
  cloud_ = frame.cloud;
  planes_ = planes;
  view_ = foreground::FrameView{};
  view_.cloud = cloud_.get();
  view_.T_world_camera = T;
  view_.stamp_s = frame.stamp_s;
  view_.frame_index = frame_index;
  view_.planes = &planes_;
  view_.up_world = up_direction(configured_up, planes, T);
  K_ = frame.intrinsics;
  view_.K = K_ ? &*K_ : nullptr;
  detection_ = foreground::HandDetection{};
  if (!config_.enabled) return frame;

  const auto t_hands = Clock::now();
  if (config_.hands.enabled && frame.has_color && frame.cloud->height > 1) {
    // A moving camera: the remembered planes move with it (a hand-held room sequence otherwise
    // searched its planes again in every frame).
    CameraView& seen_by = cameras_[camera];
    if (frame.T_world_camera && seen_by.last_pose) {
      const Pose T_now_prev = frame.T_world_camera->inverse() * *seen_by.last_pose;
      if (!T_now_prev.matrix().isIdentity(1e-9)) seen_by.hand_memory.camera_moved(T_now_prev.cast<float>());
    }
    seen_by.last_pose = frame.T_world_camera;
    detection_ = foreground::detect_hands(*frame.cloud, config_.hands, &seen_by.hand_memory);
    drop_static_hands(*frame.cloud, T, occupied);
  }
  view_.hands = &detection_;
  result.hands_ms = ms_since(t_hands);
  result.hands = detection_.hands.size();
  if (!detection_.labels.empty()) hands_ = summarise(detection_, *frame.cloud, T, frame_index, frame.stamp_s);

  const auto t_track = Clock::now();
  std::vector<int> blank = tracker_.track(view_);
  result.foreground_ms = ms_since(t_track);
  for (std::size_t i = 0; i < detection_.labels.size(); ++i) {
    if (detection_.labels[i] != foreground::AgentLabel::kNone) blank.push_back(static_cast<int>(i));
  }
  if (blank.empty()) return frame;
  auto masked = std::make_shared<Cloud>(*frame.cloud);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i : blank) {
    PointT& p = masked->points[static_cast<std::size_t>(i)];
    p.x = p.y = p.z = nan;
  }
  Frame seen = frame;
  seen.cloud = masked;
  return seen;
}

foreground::ForegroundUpdate ForegroundStage::update(const std::vector<ObjectCluster>& clusters,
                                                     const std::vector<TrackedObject>& known, FrameResult& result) {
  if (!config_.enabled || !cloud_) return {};
  const auto t0 = Clock::now();
  auto out = tracker_.update(view_, clusters, known);
  // Where a hand is or just was, what changed is the person's doing (a hand the detector missed
  // for a frame or two went into the map, and leaves it as it moves on).
  if (hands_.frame_index == view_.frame_index) {
    for (const auto& h : hands_.hands) recent_hands_.push_back({view_.frame_index, h.box_world.grown(kHandQuietM)});
    if (hands_.person_box_world) recent_hands_.push_back({view_.frame_index, hands_.person_box_world->grown(kPersonQuietM)});
  }
  while (!recent_hands_.empty() && recent_hands_.front().first + kHandQuietFrames < view_.frame_index) recent_hands_.pop_front();
  for (const auto& [frame, box] : recent_hands_) out.quiet_boxes.push_back(box);
  result.foreground_ms += ms_since(t0);
  return out;
}

void ForegroundStage::reset() {
  tracker_.reset();
  cameras_.clear();
  recent_hands_.clear();
  hands_ = HandsSeen{};
  cloud_.reset();
}

}  // namespace scenewatch::pipeline
