#pragma once
/// Relocalization against the memory's keyframes without a prior (the seed's homing, D5.1
/// section 4.1.2): the frame's ORB features are matched with every keyframe's (Lowe's ratio
/// test), the keyframes with the most matches are candidates, and each candidate's matches,
/// back-projected with depth on both sides, give a rigid motion by Umeyama inside RANSAC. The
/// caller refines a hypothesis densely and verifies it (Localizer).
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "scenewatch/background/appearance.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/localization/keyframe_features.h"
#include "scenewatch/localization/rigid_ransac.h"

namespace scenewatch::localization {

struct RelocalizerConfig {
  FeatureConfig features;
  RansacConfig ransac;
  /// Keyframes with the most ratio-test matches of the frame's strongest `retrieval_features`
  /// that all of its features are matched with, and RANSAC is run on.
  std::size_t candidate_keyframes = 3;
  std::size_t retrieval_features = 200;
  /// Lowe's ratio test (IJCV 2004): a match counts when its Hamming distance is below this
  /// fraction of the second best's.
  double match_ratio = 0.8;
  /// A fit with fewer inlier matches than this is no hypothesis.
  std::size_t min_inliers = 12;
  /// A match agrees with a motion within this many sigmas of the two points' noise (the sensor
  /// model's axial noise at their depth; lateral, colour-depth registration and keypoint scale
  /// in pixels at their depth).
  double tolerance_sigmas = 3.0;
};

Status validate(const RelocalizerConfig& config);

/// One candidate placement of the frame.
struct Hypothesis {
  Pose T_world_camera = Pose::Identity();
  std::shared_ptr<const background::Keyframe> keyframe;
  std::size_t matches = 0, inliers = 0;
  double rms_m = 0.0;
};

/// Keeps each keyframe's features by id (extracted on first use). NOT thread safe: one writer.
class Relocalizer {
 public:
  explicit Relocalizer(RelocalizerConfig config = {}, SensorModel sensor = {});

  /// Hypotheses for a frame's features among the keyframes, most inliers first.
  /// `focal_px`: the frame's focal length.
  std::vector<Hypothesis> hypotheses(const ViewFeatures& frame, double focal_px,
                                     const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes);
  /// The features of a keyframe (cached by id).
  const ViewFeatures& features(const background::Keyframe& keyframe);

  /// The keyframes' features to save with the model: those extracted so far. Keyframes no
  /// relocalization has needed yet (all of them under `localization.mode: given`) are saved
  /// without: extracting them would hold every save up by ~15 ms a keyframe, and they are
  /// extracted on first use after a load instead.
  std::vector<SavedFeatures> to_save(const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes) const;
  /// Takes saved features for the loaded keyframes, each matched by its pose (within 1 mm and
  /// 0.1 degrees); keyframes without a record get theirs extracted on first use. Returns how many were taken.
  std::size_t restore(const std::vector<SavedFeatures>& saved, const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes);
  void reset() { cache_.clear(); }
  std::size_t cached() const { return cache_.size(); }
  const RelocalizerConfig& config() const { return config_; }
  const SensorModel& sensor() const { return sensor_; }

 private:
  /// Ratio-test matches of the frame's first `frame_limit` features (the strongest) with a
  /// keyframe's, as 3D pairs (keyframe: target).
  std::vector<Correspondence> correspondences(const ViewFeatures& frame, double frame_focal_px, const ViewFeatures& keyframe,
                                              double keyframe_focal_px, std::size_t frame_limit) const;
  double tolerance_m(const Eigen::Vector3f& p, float pixel_size, double focal_px) const;

  RelocalizerConfig config_;
  SensorModel sensor_;
  std::map<std::uint64_t, ViewFeatures> cache_;
};

}  // namespace scenewatch::localization
