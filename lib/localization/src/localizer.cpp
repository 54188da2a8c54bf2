// Per-camera localization against the memory's keyframes: priors, alignment, lost and found.
#include "scenewatch/localization/localizer.h"

#include <chrono>
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace scenewatch::localization {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

constexpr std::size_t kCachedReferences = 16;
constexpr std::size_t kRememberedPlacements = 64;
constexpr std::size_t kRememberedKeyframes = 4096;

bool same_pose(const Pose& a, const Pose& b) { return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < 1e-9; }

bool organized_with_intrinsics(const Frame& f) {
  return f.cloud && f.intrinsics && f.intrinsics->valid() && f.cloud->height > 1 &&
         f.cloud->width == static_cast<std::uint32_t>(f.intrinsics->width) &&
         f.cloud->height == static_cast<std::uint32_t>(f.intrinsics->height);
}

/// A frame's pyramid in `slot`, built on first use: once per frame whichever step asks first (a
/// reference one when tracking, as it becomes the camera's previous frame).
const RgbdPyramid& frame_pyramid(std::shared_ptr<const RgbdPyramid>& slot, const Frame& f, const SensorModel& sensor,
                                 const PyramidConfig& config, bool reference) {
  if (!slot) slot = std::make_shared<const RgbdPyramid>(build_pyramid(*f.cloud, *f.intrinsics, sensor, config, reference));
  return *slot;
}

}  // namespace

struct Localizer::Track {
  bool started = false;
  Pose last = Pose::Identity();      ///< the last placed pose
  Pose motion = Pose::Identity();    ///< last^-1 x the one before's successor: the camera's last step
  Pose T_world_odom = Pose::Identity();
  /// Variance of the camera's placement relative to the memory (refine mode): m^2, rad^2.
  double var_m2 = 0.0, var_rad2 = 0.0;
  bool homed = false;       ///< placed against the memory (or started it) since the camera's first frame
  int lost_in_row = 0;
  /// Without given poses: the last placed frame, prepared as a reference, for the frame-to-frame step.
  std::shared_ptr<const RgbdPyramid> previous;
  Localization result;
};

Status validate(const Config& c) {
  if (auto st = validate(c.alignment); !st) return st;
  if (c.pyramid.levels != static_cast<int>(c.alignment.iterations.size()))
    return invalid_argument("localization.levels: " + std::to_string(c.pyramid.levels) + " levels but " +
                            std::to_string(c.alignment.iterations.size()) + " entries in localization.iterations");
  if (c.pyramid.finest_halvings < 0 || c.pyramid.finest_halvings > 3)
    return invalid_argument("localization.finest_halvings: must be in [0, 3]");
  if (!(c.min_inlier_fraction >= 0 && c.min_inlier_fraction <= 1))
    return invalid_argument("localization.min_inlier_fraction: must be in [0, 1]");
  if (!(c.min_conditioning >= 0 && c.min_conditioning < 1)) return invalid_argument("localization.min_conditioning: must be in [0, 1)");
  if (!(c.max_correction_m > 0) || !(c.max_correction_deg > 0 && c.max_correction_deg <= 180))
    return invalid_argument("localization.max_correction_m / max_correction_deg: must be > 0 (degrees at most 180)");
  if (!(c.drift_m_per_frame >= 0 && c.drift_m_per_frame <= 1) || !(c.drift_deg_per_frame >= 0 && c.drift_deg_per_frame <= 90))
    return invalid_argument("localization.drift_m_per_frame / drift_deg_per_frame: must be in [0, 1] m and [0, 90] degrees");
  if (!(c.noise_m >= 0 && c.noise_m <= 1) || !(c.noise_deg >= 0 && c.noise_deg <= 90))
    return invalid_argument("localization.noise_m / noise_deg: must be in [0, 1] m and [0, 90] degrees");
  if (c.reference_keyframes < 1 || c.reference_keyframes > 8)
    return invalid_argument("localization.reference_keyframes: must be in [1, 8]");
  if (c.rehome_after_lost_frames < 1 || c.rehome_after_lost_frames > 1000)
    return invalid_argument("localization.rehome_after_lost_frames: must be in [1, 1000]");
  return validate(c.relocalization);
}

Result<LocalizationMode> parse_mode(const std::string& name) {
  if (name == "given") return LocalizationMode::kGiven;
  if (name == "refine") return LocalizationMode::kRefine;
  if (name == "track") return LocalizationMode::kTrack;
  return invalid_argument("localization mode '" + name + "': expected given, refine or track");
}

const char* mode_name(LocalizationMode mode) {
  switch (mode) {
    case LocalizationMode::kGiven: return "given";
    case LocalizationMode::kRefine: return "refine";
    case LocalizationMode::kTrack: return "track";
  }
  return "?";
}

const char* state_name(State state) {
  switch (state) {
    case State::kGiven: return "given";
    case State::kStarting: return "starting";
    case State::kTracking: return "tracking";
    case State::kLost: return "lost";
  }
  return "?";
}

Localizer::Localizer(Config config, SensorModel sensor)
    : config_(std::move(config)), sensor_(std::move(sensor)), relocalizer_(config_.relocalization, sensor_) {}

std::shared_ptr<const RgbdPyramid> Localizer::reference(const background::Keyframe& keyframe) {
  ++uses_;
  if (auto it = references_.find(keyframe.id); it != references_.end()) {
    it->second.second = uses_;
    return it->second.first;
  }
  auto pyramid = std::make_shared<const RgbdPyramid>(
      build_pyramid(keyframe.depth, keyframe.color, keyframe.intrinsics, sensor_, config_.pyramid, true));
  if (references_.size() >= kCachedReferences) {
    auto oldest = references_.begin();
    for (auto it = references_.begin(); it != references_.end(); ++it)
      if (it->second.second < oldest->second.second) oldest = it;
    references_.erase(oldest);
  }
  references_[keyframe.id] = {pyramid, uses_};
  return pyramid;
}

Localization Localizer::localize(const Frame& frame, std::uint32_t camera, const KeyframeSource& keyframes) {
  return localize(frame, camera, keyframes, {});
}

bool Localizer::must_relocalize(const Track& track, LocalizationMode mode) const {
  if (mode == LocalizationMode::kGiven) return false;
  if (!track.homed) return true;  // homing: the camera's frame is not the memory's yet
  if (mode == LocalizationMode::kTrack) return track.result.state == State::kLost;
  return track.lost_in_row >= config_.rehome_after_lost_frames;
}

bool Localizer::accept(Localization& r, const Alignment& a, const Pose& T_world_reference, const std::string& what) const {
  // Re-orthonormalised: each frame's pose is the last one times a step, and the track's motion
  // is last^-1 x pose, where an Isometry's inverse assumes an exact rotation. Rounding error left
  // in the rotation grew about 2.4-fold per frame while the camera kept its motion: on
  // redkitchen_long the rotation's determinant reached 1.006 by frame 50 (a pose that scales the
  // scene by 0.2 %, 5 mm at 2.5 m), and a camera that never stops would diverge.
  r.T_world_camera = pose_from_matrix((T_world_reference * a.T_reference_current).matrix());
  r.inlier_fraction = a.inlier_fraction;
  r.residual_m = a.residual_m;
  r.conditioning = a.conditioning;
  const Mat6 A = twist_adjoint(T_world_reference);
  r.covariance = A * a.covariance * A.transpose();
  if (a.inlier_fraction < config_.min_inlier_fraction) {
    r.reason = "alignment with " + what + " poor: " +
               std::to_string(static_cast<int>(std::lround(100 * a.inlier_fraction))) + " % of the depth pixels agree";
    return false;
  }
  if (a.conditioning < config_.min_conditioning) {
    r.reason = "the view does not constrain every motion (conditioning " + std::to_string(a.conditioning) + ")";
    return false;
  }
  r.state = State::kTracking;
  r.reason.clear();
  return true;
}

Localization Localizer::relocalize(const Frame& frame, const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes) {
  const auto t0 = std::chrono::steady_clock::now();
  Localization out;
  out.mode = frame.localization.value_or(config_.mode);
  out.given = frame.T_world_camera;
  out.state = State::kLost;
  out.T_world_camera = frame.pose_or_identity();
  auto finish = [&](Localization r) {
    r.relocalization_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  const ViewFeatures features = extract_features(frame, sensor_, config_.relocalization.features);
  if (features.size() < config_.relocalization.min_inliers) {
    out.reason = "relocalization: " + std::to_string(features.size()) + " features with depth in the frame";
    return finish(out);
  }
  const auto hypotheses = relocalizer_.hypotheses(features, frame.intrinsics->fx, keyframes);
  if (hypotheses.empty()) {
    out.reason = "relocalization: no keyframe shares " + std::to_string(config_.relocalization.min_inliers) + " consistent features";
    return finish(out);
  }
  const RgbdPyramid current = build_pyramid(*frame.cloud, *frame.intrinsics, sensor_, config_.pyramid, false);
  Localization best = out;
  for (const auto& h : hypotheses) {
    // Seed section 4.1.2: the feature hypothesis refined densely, then verified against the view.
    const Alignment a = align(*reference(*h.keyframe), current, h.keyframe->T_world_camera.inverse() * h.T_world_camera, sensor_,
                              config_.alignment);
    Localization r = out;
    r.relocalized = true;
    r.feature_matches = h.matches;
    r.feature_inliers = h.inliers;
    r.reference_keyframe = h.keyframe->id;
    if (accept(r, a, h.keyframe->T_world_camera, "keyframe " + std::to_string(h.keyframe->id))) return finish(r);
    r.state = State::kLost;
    r.T_world_camera = out.T_world_camera;
    r.reason = "relocalization: " + r.reason;
    if (best.reference_keyframe == 0 || r.inlier_fraction > best.inlier_fraction) best = r;
  }
  return finish(best);
}

std::vector<std::uint32_t> Localizer::cameras() const {
  std::vector<std::uint32_t> out;
  for (const auto& [id, track] : tracks_) out.push_back(id);
  return out;
}

/// One call of localize(): the camera's track and what the frame's placement is built from.
struct Localizer::Attempt {
  Attempt(const Frame& f, Track& t, std::chrono::steady_clock::time_point start) : frame(f), track(t), t0(start) {}
  const Frame& frame;
  Track& track;
  std::chrono::steady_clock::time_point t0;
  bool use_given = false;
  Pose prior = Pose::Identity();
  // In `refine` mode: where the running correction puts this frame (the given pose's own noise
  // left out), and how uncertain the frame's placement is; the prior's until an alignment says more.
  std::optional<Pose> odom_pose;
  double placed_var_m2 = 0, placed_var_rad2 = 0;
  /// The frame's pyramid, when built (a reference one without given poses: it is the next frame's previous).
  std::shared_ptr<const RgbdPyramid> current;
};

Localization Localizer::localize(const Frame& frame, std::uint32_t camera, const KeyframeSource& keyframes, const AllKeyframes& all) {
  const auto t0 = std::chrono::steady_clock::now();
  auto& slot = tracks_[camera];
  if (!slot) slot = std::make_shared<Track>();
  Track& track = *slot;
  Localization out;
  out.mode = frame.localization.value_or(config_.mode);
  out.given = frame.T_world_camera;
  Attempt at(frame, track, t0);
  at.use_given = out.mode != LocalizationMode::kTrack && frame.T_world_camera.has_value();
  // The prior: the given pose in the memory's frame, else the last pose moved on by the last step.
  at.prior = at.use_given ? track.T_world_odom * *frame.T_world_camera
                          : (track.started ? Pose(track.last * track.motion) : Pose::Identity());
  out.T_world_camera = at.prior;
  out.T_world_odom = track.T_world_odom;
  const double noise_rad = config_.noise_deg * M_PI / 180.0;
  at.placed_var_m2 = track.var_m2 + config_.noise_m * config_.noise_m;
  at.placed_var_rad2 = track.var_rad2 + noise_rad * noise_rad;
  if (out.mode == LocalizationMode::kGiven) {
    out.state = State::kGiven;
    out.T_world_camera = frame.pose_or_identity();
    return finish(at, out);
  }
  if (!organized_with_intrinsics(frame)) {
    out.state = State::kGiven;
    out.reason = "not an organized frame with intrinsics: its pose is used as given";
    out.T_world_camera = frame.pose_or_identity();
    return finish(at, out);
  }
  // The keyframe list is asked for only when the camera must relocalize: most frames do not.
  if (all && must_relocalize(track, out.mode)) {
    const auto every = all();
    if (!every.empty()) return finish(at, relocalize_track(at, out.mode, every));
  }
  return finish(at, align_with_keyframes(at, out, keyframes));
}

Localization Localizer::relocalize_track(Attempt& at, LocalizationMode mode,
                                         const std::vector<std::shared_ptr<const background::Keyframe>>& every) {
  Localization r = relocalize(at.frame, every);
  r.mode = mode;
  if (!r.placed()) {
    r.T_world_camera = at.prior;  // placed nowhere new
    if (!at.track.homed) r.reason = "homing: " + r.reason;
    return r;
  }
  if (at.use_given) {
    // The relocalized pose starts the camera's correction anew: its error is the alignment's.
    at.track.var_m2 = r.residual_m * r.residual_m;
    at.track.var_rad2 = at.track.var_m2;
    at.placed_var_m2 = at.track.var_m2;
    at.placed_var_rad2 = at.track.var_rad2;
    const auto from_given = background::view_distance(r.T_world_camera, *at.frame.T_world_camera);
    r.correction_m = from_given.translation_m;
    r.correction_deg = from_given.rotation_deg;
  }
  return r;
}

Localization Localizer::align_with_keyframes(Attempt& at, const Localization& out, const KeyframeSource& keyframes) {
  const Frame& frame = at.frame;
  const Track& track = at.track;
  const bool tracking = !at.use_given;
  // Without a given pose the frame is aligned to the camera's previous frame: a frame's motion
  // lies inside the alignment's basin, where a keyframe up to a spacing away may not (on
  // redkitchen_long, keyframes 5 cm and 2.5 degrees off led it into false minima and the track
  // diverged). The keyframes place the frame only when that step fails (docs/localization.md).
  if (tracking && track.started && track.previous)
    if (auto step = step_from_previous(at, out)) return *step;
  const Pose& prior = at.prior;
  auto candidates = keyframes ? keyframes(prior, config_.reference_keyframes) : decltype(keyframes(prior, 1)){};
  if (at.use_given) {
    // Of the keyframes near the prior, the one placed most surely is tried first: an older one,
    // placed before the chain of refined keyframes grew, anchors the frame better than the newest.
    std::stable_sort(candidates.begin(), candidates.end(), [&](const auto& a, const auto& b) {
      return keyframe_variance(*a).first < keyframe_variance(*b).first;
    });
  }
  if (candidates.empty()) {
    Localization r = out;
    r.state = State::kStarting;
    r.reason = "no keyframe near the prior to align with";
    // With a given pose, a view the memory has no keyframe of is new ground: the prior places
    // it, so that the memory grows there. Without one, a camera that had been placed and now
    // finds no keyframe near its prior has left the memory's views: that is lost.
    if (!at.use_given && track.started && track.result.state == State::kTracking) {
      r.state = State::kLost;
      r.reason = "no keyframe of the memory sees towards the prior";
    }
    // A camera starting without a pose and without keyframes (a memory that keeps none) steps
    // from this frame on.
    if (tracking && r.placed()) frame_pyramid(at.current, frame, sensor_, config_.pyramid, true);
    return r;
  }
  const RgbdPyramid& current = frame_pyramid(at.current, frame, sensor_, config_.pyramid, tracking);
  Localization best = out;
  best.state = State::kLost;
  std::optional<Alignment> aligned;
  const background::Keyframe* aligned_to = nullptr;  // the keyframe of `aligned`
  for (const auto& keyframe : candidates) {
    const auto ref = reference(*keyframe);
    Alignment a = align(*ref, current, keyframe->T_world_camera.inverse() * prior, sensor_, config_.alignment);
    if (tracking && track.started) {
      // Without a given pose the prior assumes the camera kept its last motion; when it stopped
      // or turned back, that prior lies twice as far off as the last pose. Both are tried; the
      // one more of the frame agrees with wins.
      Alignment still = align(*ref, current, keyframe->T_world_camera.inverse() * track.last, sensor_, config_.alignment);
      if (still.inlier_fraction > a.inlier_fraction) a = std::move(still);
    }
    Localization r = out;
    r.reference_keyframe = keyframe->id;
    if (accept(r, a, keyframe->T_world_camera, "keyframe " + std::to_string(keyframe->id))) {
      best = r;
      aligned = a;
      aligned_to = keyframe.get();
      break;
    }
    if (best.reference_keyframe == 0 || r.inlier_fraction > best.inlier_fraction) best = r;
  }
  if (!aligned) {
    best.state = State::kLost;
    best.T_world_camera = prior;  // a lost frame is placed nowhere new
    return best;
  }
  if (at.use_given) weigh_against_given(at, best, *aligned, *aligned_to);
  return best;
}

std::optional<Localization> Localizer::step_from_previous(Attempt& at, const Localization& out) {
  Track& track = at.track;
  const RgbdPyramid& current = frame_pyramid(at.current, at.frame, sensor_, config_.pyramid, true);
  // From the last motion, and from standing still: a wrong rotation in the last motion (0.6-0.9
  // degrees a frame on redkitchen_long) can lead the alignment into a false minimum where fewer
  // pixels agree. The one more of the frame agrees with wins. They are told apart after the
  // coarsest level alone (about a quarter of a full alignment, with the agreement measured on
  // the finest), and only the winner goes on through the finer levels: on redkitchen_long the
  // same trajectory as two full alignments, to 0.01 mm RMSE.
  AlignmentConfig coarse = config_.alignment;
  std::fill(coarse.iterations.begin() + 1, coarse.iterations.end(), 0);
  const Alignment moving = align(*track.previous, current, track.motion, sensor_, coarse);
  const Alignment still = align(*track.previous, current, Pose::Identity(), sensor_, coarse);
  const Pose& start = still.inlier_fraction > moving.inlier_fraction ? still.T_reference_current : moving.T_reference_current;
  Alignment a = align(*track.previous, current, start, sensor_, config_.alignment);
  Localization r = out;
  if (!accept(r, a, track.last, "the previous frame")) return std::nullopt;
  return r;
}

void Localizer::weigh_against_given(Attempt& at, Localization& best, const Alignment& aligned,
                                    const background::Keyframe& aligned_to) {
  const Fused f = fuse_with_prior(at.track, at.prior, best.T_world_camera, aligned, aligned_to);
  best.T_world_camera = f.pose;
  best.alignment_rejected = f.rejected;
  at.odom_pose = f.odom_pose;
  at.placed_var_m2 = f.var_m2;
  at.placed_var_rad2 = f.var_rad2;
  const auto from_given = background::view_distance(best.T_world_camera, *at.frame.T_world_camera);
  best.correction_m = from_given.translation_m;
  best.correction_deg = from_given.rotation_deg;
  const auto moved = background::view_distance(best.T_world_camera, at.prior);
  if (moved.translation_m > config_.max_correction_m || moved.rotation_deg > config_.max_correction_deg) {
    best.state = State::kLost;
    best.reason = "the alignment moved the given pose too far (" + std::to_string(moved.translation_m) + " m, " +
                  std::to_string(moved.rotation_deg) + " deg)";
    best.T_world_camera = at.prior;
    at.odom_pose.reset();
  }
}

Localization Localizer::finish(Attempt& at, Localization r) {
  Track& track = at.track;
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - at.t0).count();
  if (r.placed()) {
    if (track.started && !r.relocalized) track.motion = track.last.inverse() * r.T_world_camera;
    if (r.relocalized) track.motion = Pose::Identity();
    track.last = r.T_world_camera;
    track.previous = at.use_given ? nullptr : at.current;  // a relocalized frame's is not built: null
    track.started = true;
    track.homed = true;
    track.lost_in_row = 0;
    if (at.use_given) {
      const Pose before = track.T_world_odom;
      track.T_world_odom = at.odom_pose.value_or(r.T_world_camera) * at.frame.T_world_camera->inverse();
      if (r.mode == LocalizationMode::kRefine) remember_placement(r.T_world_camera, at.placed_var_m2, at.placed_var_rad2);
      const auto moved = background::view_distance(before, track.T_world_odom);
      r.odom_change_m = moved.translation_m;
      r.odom_change_deg = moved.rotation_deg;
    }
    r.T_world_odom = track.T_world_odom;
  } else {
    ++track.lost_in_row;
  }
  r.homed = track.homed;
  track.result = r;
  return r;
}

// Refine mode. The given pose G is the true one moved by the pose source's drift D (a random walk:
// drift_m_per_frame, drift_deg_per_frame) and by its own noise W (independent per frame:
// noise_m, noise_deg); the running correction T_world_odom estimates D^-1. The alignment places
// the frame against a keyframe; its error is the alignment's (taken as its residual, a point's
// noise: the covariance of the least-squares fit is far smaller than its real error, which
// correlated noise and depth distortion make) plus the keyframe's own placement error, so that
// a chain of keyframes placed by alignments is not taken for ground truth. The frame is placed by
// weighing the two (prior: drift and noise; measurement: alignment and keyframe); the correction
// takes only the drift's share of the difference, so one frame's noise does not move the next
// frames' prior. Translation and rotation are filtered apart, each with scalar gains; a
// measurement more than three sigmas from the prior is not believed.
Localizer::Fused Localizer::fuse_with_prior(Track& track, const Pose& prior, const Pose& measured, const Alignment& a,
                                            const background::Keyframe& keyframe) {
  const double drift_rad = config_.drift_deg_per_frame * M_PI / 180.0, noise_rad = config_.noise_deg * M_PI / 180.0;
  track.var_m2 += config_.drift_m_per_frame * config_.drift_m_per_frame;
  track.var_rad2 += drift_rad * drift_rad;
  const auto [keyframe_m2, keyframe_rad2] = keyframe_variance(keyframe);
  const double depth = a.mean_depth_m > 0 ? a.mean_depth_m : 1.0;
  const double prior_m2 = track.var_m2 + config_.noise_m * config_.noise_m, prior_rad2 = track.var_rad2 + noise_rad * noise_rad;
  const double meas_m2 = a.residual_m * a.residual_m + keyframe_m2;
  const double meas_rad2 = a.residual_m * a.residual_m / (depth * depth) + keyframe_rad2;
  const double sum_m2 = prior_m2 + meas_m2, sum_rad2 = prior_rad2 + meas_rad2;
  const Eigen::Vector3d dt = measured.translation() - prior.translation();
  const Eigen::Quaterniond qp(prior.linear()), qm(measured.linear());
  const double dr = qp.angularDistance(qm);
  Fused f;
  f.pose = f.odom_pose = prior;
  f.var_m2 = prior_m2;
  f.var_rad2 = prior_rad2;
  f.rejected = dt.norm() > 3.0 * std::sqrt(sum_m2) || dr > 3.0 * std::sqrt(sum_rad2);
  if (f.rejected) return f;
  const auto moved = [&](double k_t, double k_r) {
    Pose p = Pose::Identity();
    p.linear() = qp.slerp(k_r, qm).normalized().toRotationMatrix();
    p.translation() = prior.translation() + k_t * dt;
    return p;
  };
  f.pose = moved(prior_m2 / sum_m2, prior_rad2 / sum_rad2);
  f.odom_pose = moved(track.var_m2 / sum_m2, track.var_rad2 / sum_rad2);
  f.var_m2 = prior_m2 * meas_m2 / sum_m2;
  f.var_rad2 = prior_rad2 * meas_rad2 / sum_rad2;
  track.var_m2 -= track.var_m2 * track.var_m2 / sum_m2;
  track.var_rad2 -= track.var_rad2 * track.var_rad2 / sum_rad2;
  return f;
}

std::pair<double, double> Localizer::keyframe_variance(const background::Keyframe& keyframe) {
  if (auto it = keyframe_variances_.find(keyframe.id); it != keyframe_variances_.end()) return it->second;
  std::pair<double, double> v{0.0, 0.0};
  for (auto it = placements_.rbegin(); it != placements_.rend(); ++it)
    if (same_pose(it->pose, keyframe.T_world_camera)) {
      v = {it->var_m2, it->var_rad2};
      break;
    }
  if (keyframe_variances_.size() >= kRememberedKeyframes) keyframe_variances_.erase(keyframe_variances_.begin());
  keyframe_variances_[keyframe.id] = v;
  return v;
}

void Localizer::remember_placement(const Pose& pose, double var_m2, double var_rad2) {
  placements_.push_back({pose, var_m2, var_rad2});
  if (placements_.size() > kRememberedPlacements) placements_.pop_front();
}

std::optional<Localization> Localizer::last(std::uint32_t camera) const {
  auto it = tracks_.find(camera);
  if (it == tracks_.end() || !it->second) return std::nullopt;
  return it->second->result;
}

void Localizer::forget_camera(std::uint32_t camera) { tracks_.erase(camera); }

void Localizer::reset() {
  tracks_.clear();
  references_.clear();
  placements_.clear();
  keyframe_variances_.clear();
  relocalizer_.reset();
}

}  // namespace scenewatch::localization
