#pragma once
/// Where each frame was taken, against the memory (issue 29; DESIGN.md's `localization`). Per
/// camera, a frame is aligned to the memory's nearest keyframe from a prior: in `refine` mode the
/// given pose carried by the camera's running correction (T_world_odom: the given poses' frame
/// and drift undone). In `track` mode (or a frame without a pose) a frame is aligned to the
/// camera's previous frame, and to the keyframes near the last pose moved on by the camera's last
/// motion only when that fails. A poor alignment leaves the camera `lost`: its frame must change nothing.
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/background/appearance.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/localization/dense_alignment.h"
#include "scenewatch/localization/relocalizer.h"
#include "scenewatch/localization/rgbd_pyramid.h"

namespace scenewatch::localization {

struct Config {
  /// `given` by default: `refine` and `track` do not yet meet their accuracy on real data (docs/localization.md).
  LocalizationMode mode = LocalizationMode::kGiven;
  PyramidConfig pyramid;
  AlignmentConfig alignment;
  /// An alignment whose inliers (three noise sigmas) are fewer than this fraction of the frame's
  /// depth pixels does not place the frame: the view is not the memory's, or the prior too far.
  double min_inlier_fraction = 0.3;
  /// ... nor one the scene does not constrain in every direction (a wall alone): the smallest
  /// eigenvalue of the normalised information against the largest.
  double min_conditioning = 1e-3;
  /// In `refine` mode, a correction of the given pose larger than this is not believed: the
  /// frame is lost (a jump of the pose source or a wrong alignment; drift is far smaller).
  double max_correction_m = 0.3;
  double max_correction_deg = 15.0;
  /// Keyframes tried in turn, nearest to the prior first, until one aligns.
  std::size_t reference_keyframes = 2;
  /// In `refine` mode, how far the given poses may drift from frame to frame, 1 sigma: the pose
  /// source's drift per frame (an arm's kinematics or motion capture: well under a millimetre; a
  /// robot's odometry: a few). The refined pose weighs the alignment against the given pose by
  /// this drift and the alignment's own error (its point-to-plane residual), as a Kalman filter
  /// of the camera's offset from its given pose; an alignment that disagrees with it by more than
  /// three sigmas is not believed (the prior is used).
  double drift_m_per_frame = 0.001;
  double drift_deg_per_frame = 0.05;
  /// In `refine` mode, the given poses' own noise, 1 sigma, independent from frame to frame (a
  /// motion-capture marker's jitter, an arm's encoder noise, a pose estimate's scatter): it weighs
  /// each given pose against its alignment but, unlike the drift, is not carried into the
  /// running correction of the next frames. 0: the given poses carry drift only.
  double noise_m = 0.0;
  double noise_deg = 0.0;
  /// Relocalization from keyframe features (homing): a camera's first frames when the memory
  /// already has keyframes (a loaded model), every lost frame in `track` mode, and in `refine`
  /// mode after this many lost frames in a row (the pose source jumped for good).
  RelocalizerConfig relocalization;
  int rehome_after_lost_frames = 3;
};

Status validate(const Config& config);
/// "given", "refine", "track"; an error naming them for anything else.
Result<LocalizationMode> parse_mode(const std::string& name);
const char* mode_name(LocalizationMode mode);

enum class State {
  kGiven,     ///< mode `given`: the pose as it came
  kStarting,  ///< no keyframe of the memory sees towards the prior (a new view, or the first frames): the prior is used
  kTracking,  ///< aligned to the memory
  kLost,      ///< the last alignment failed: the frame must change nothing
};
const char* state_name(State state);

/// Where one frame was placed, and how well.
struct Localization {
  LocalizationMode mode = LocalizationMode::kGiven;
  State state = State::kGiven;
  Pose T_world_camera = Pose::Identity();  ///< the pose the memory uses (the prior when lost)
  std::optional<Pose> given;               ///< the frame's own pose, if it had one
  /// In `refine` mode, how far the used pose lies from the given one.
  double correction_m = 0.0, correction_deg = 0.0;
  /// The camera's running correction of its given poses' frame: T_world_camera = T_world_odom x given.
  Pose T_world_odom = Pose::Identity();
  double inlier_fraction = 0.0, residual_m = 0.0, conditioning = 0.0;
  /// In `refine` mode: the alignment disagreed with the given pose beyond its drift, and the
  /// frame was placed at the prior instead.
  bool alignment_rejected = false;
  /// Covariance of the pose's error as a twist in the world frame (translation, rotation).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::uint64_t reference_keyframe = 0;  ///< the keyframe it was aligned to (0: none)
  /// This frame was placed by relocalization (feature matches, then dense alignment), not from its prior.
  bool relocalized = false;
  /// The camera has been placed against the memory since it started (or started an empty memory):
  /// until then its frames are relocalized and, when that fails, lost.
  bool homed = false;
  std::size_t feature_matches = 0, feature_inliers = 0;  ///< of the relocalization, when one ran
  double relocalization_ms = 0.0;
  /// How far this frame's placement moved the camera's T_world_odom, metres and degrees.
  double odom_change_m = 0.0, odom_change_deg = 0.0;
  std::string reason;                    ///< why it is lost, or starting
  double ms = 0.0;
  /// True when the frame may change the memory.
  bool placed() const { return state != State::kLost; }
};

/// Up to n keyframes near a pose, nearest first (AppearanceMemory::nearest).
using KeyframeSource = std::function<std::vector<std::shared_ptr<const background::Keyframe>>(const Pose&, std::size_t)>;
/// Every keyframe of the memory (AppearanceMemory::keyframes), for relocalization.
using AllKeyframes = std::function<std::vector<std::shared_ptr<const background::Keyframe>>()>;

/// NOT thread safe: one writer (the pipeline's frame loop).
class Localizer {
 public:
  explicit Localizer(Config config = {}, SensorModel sensor = {});

  /// Places a frame of `camera`. Frames that cannot be aligned (no intrinsics, not organized)
  /// keep their given pose (state kGiven, with the reason).
  Localization localize(const Frame& frame, std::uint32_t camera, const KeyframeSource& keyframes);
  /// The same, with relocalization against `all` when the camera is not homed or lost (see Config).
  Localization localize(const Frame& frame, std::uint32_t camera, const KeyframeSource& keyframes, const AllKeyframes& all);
  /// Relocalizes a frame against the keyframes without a prior: feature hypotheses, each refined
  /// densely and verified (Config::min_inlier_fraction, min_conditioning). State kTracking with
  /// the pose when found, else kLost with the reason. The camera's track does not change.
  Localization relocalize(const Frame& frame, const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes);
  /// The cameras that sent frames, in id order.
  std::vector<std::uint32_t> cameras() const;
  /// Keyframe features (to save with the model, restore after a load).
  Relocalizer& relocalizer() { return relocalizer_; }
  const Relocalizer& relocalizer() const { return relocalizer_; }
  /// The last result of a camera, if it sent a frame.
  std::optional<Localization> last(std::uint32_t camera) const;
  void forget_camera(std::uint32_t camera);
  void reset();
  const Config& config() const { return config_; }

 private:
  struct Track;
  std::shared_ptr<const RgbdPyramid> reference(const background::Keyframe& keyframe);
  /// A refine-mode alignment weighed against the given pose (localizer.cpp says how).
  struct Fused {
    Pose pose = Pose::Identity();       ///< where the frame is placed
    Pose odom_pose = Pose::Identity();  ///< where the updated running correction puts it
    double var_m2 = 0, var_rad2 = 0;    ///< the placement's variance
    bool rejected = false;
  };
  Fused fuse_with_prior(Track& track, const Pose& prior, const Pose& measured, const Alignment& alignment,
                        const background::Keyframe& keyframe);
  /// How uncertain a keyframe's pose is (m^2, rad^2): the placement variance of the frame it was
  /// made from, when this localizer placed that frame in `refine` mode; 0 otherwise (a keyframe
  /// at a given or loaded pose defines the memory's frame).
  std::pair<double, double> keyframe_variance(const background::Keyframe& keyframe);
  void remember_placement(const Pose& pose, double var_m2, double var_rad2);
  bool must_relocalize(const Track& track, LocalizationMode mode) const;
  /// Fills r's pose and quality from an alignment with a reference view (`what` names it in the
  /// reason); true when it passes the checks.
  bool accept(Localization& r, const Alignment& a, const Pose& T_world_reference, const std::string& what) const;
  // The steps of localize() (localizer.cpp), on one frame's Attempt.
  struct Attempt;
  /// A camera that must relocalize, against every keyframe.
  Localization relocalize_track(Attempt& at, LocalizationMode mode,
                                const std::vector<std::shared_ptr<const background::Keyframe>>& every);
  /// Alignment with the keyframes near the prior; `out` is the result so far.
  Localization align_with_keyframes(Attempt& at, const Localization& out, const KeyframeSource& keyframes);
  /// Without a given pose: the frame aligned to the camera's previous frame, when that passes the checks.
  std::optional<Localization> step_from_previous(Attempt& at, const Localization& out);
  /// In `refine` or given-pose mode: the alignment fused with the given pose, or refused.
  void weigh_against_given(Attempt& at, Localization& best, const Alignment& aligned, const background::Keyframe& aligned_to);
  /// Times the result and moves the camera's track on by it.
  Localization finish(Attempt& at, Localization r);

  Config config_;
  SensorModel sensor_;
  Relocalizer relocalizer_;
  std::map<std::uint32_t, std::shared_ptr<Track>> tracks_;
  /// Pyramids of recently used keyframes by id, with the use counter of each.
  std::map<std::uint64_t, std::pair<std::shared_ptr<const RgbdPyramid>, std::uint64_t>> references_;
  std::uint64_t uses_ = 0;
  /// The last placements in `refine` mode with their variances, to find a new keyframe's.
  struct Placement {
    Pose pose;
    double var_m2 = 0, var_rad2 = 0;
  };
  std::deque<Placement> placements_;
  std::map<std::uint64_t, std::pair<double, double>> keyframe_variances_;
};

}  // namespace scenewatch::localization
