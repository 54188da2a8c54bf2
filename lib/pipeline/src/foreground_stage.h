#pragma once
// The foreground's part of a frame (issue 12): before the background stages, the hands, the
// person and the registered foreground objects are found and blanked out of the frame the
// background sees (they are neither background changes nor new objects, and never enter the
// map); after the segmentation, contacts and promotion.
#include <cstdint>
#include <deque>
#include <optional>
#include <functional>
#include <map>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/foreground/foreground_tracker.h"
#include "scenewatch/pipeline/frame_result.h"
#include "scenewatch/pipeline/scene_snapshot.h"

namespace scenewatch::pipeline {

class ForegroundStage {
 public:
  explicit ForegroundStage(const foreground::ForegroundConfig& config) : config_(config), tracker_(config) {}

  /// Finds hands and registers the foreground objects; returns the frame without their pixels
  /// (the frame itself when there are none). `planes` are the last frame's, world frame.
  /// The share of world points the background map holds occupied.
  using OccupiedFraction = std::function<double(const std::vector<Eigen::Vector3d>&, const Eigen::Vector3d& camera)>;
  /// `camera` names the frame's camera: the support planes follow each camera from its own frame
  /// to its next.
  Frame prepare(const Frame& frame, std::uint64_t frame_index, const std::vector<Plane>& planes,
                const std::optional<Eigen::Vector3d>& configured_up, const OccupiedFraction& occupied, FrameResult& result,
                std::uint32_t camera = 0);
  /// Forgets what is kept of a camera that is no longer followed.
  void forget_camera(std::uint32_t camera) { cameras_.erase(camera); }

  /// Contacts and promotion, after the segmentation (`clusters` world frame, indices into the frame).
  foreground::ForegroundUpdate update(const std::vector<ObjectCluster>& clusters, const std::vector<TrackedObject>& known,
                                      FrameResult& result);

  const HandsSeen& hands() const { return hands_; }
  /// This frame's hands, arms and person, pixel by pixel (empty labels when the frame had none to
  /// look for: no colour, not organized).
  const foreground::HandDetection& agents() const { return detection_; }
  foreground::ForegroundTracker& tracker() { return tracker_; }
  const foreground::ForegroundTracker& tracker() const { return tracker_; }
  void reset();

 private:
  foreground::ForegroundConfig config_;
  foreground::ForegroundTracker tracker_;
  struct CameraView {
    foreground::HandMemory hand_memory;  // the support planes, from frame to frame
    std::optional<Pose> last_pose;       // the camera of its frame before, for the planes to follow
  };
  std::map<std::uint32_t, CameraView> cameras_;
  // This frame's, between prepare() and update().
  foreground::HandDetection detection_;
  foreground::FrameView view_;
  std::vector<Plane> planes_;
  CloudConstPtr cloud_;
  std::optional<Intrinsics> K_;
  HandsSeen hands_;
  std::deque<std::pair<std::uint64_t, Aabb>> recent_hands_;  ///< frame, box grown by kHandQuietM
  static constexpr double kHandQuietM = 0.05;
  /// The person's box is grown more: the detection keeps to the body near the arm, and a shoulder
  /// or a head beside it is just as much the person's (hrt1: 15 cm in front of the body's box).
  static constexpr double kPersonQuietM = 0.15;
  static constexpr double kStaticHandFraction = 0.5;  ///< of a hand's points on remembered surfaces: furniture
  void drop_static_hands(const Cloud& cloud, const Pose& T, const OccupiedFraction& occupied);
  static constexpr std::uint64_t kHandQuietFrames = 15;
};

/// The world's up direction: the configured one, else the normal (turned towards the camera) of
/// the largest plane within 45 degrees of the camera's own up (its image's -y axis: a camera is
/// held roughly upright, and a wall faces it as squarely as a table does), else of the largest
/// plane, else +z. Without the camera's up a wall larger than the table in view (hrt1: 1.46 against
/// 1.36 m2) took its place in one frame and gave it back in the next.
Eigen::Vector3d up_direction(const std::optional<Eigen::Vector3d>& configured, const std::vector<Plane>& planes,
                             const Pose& T_world_camera);

/// A plane whose side facing the camera faces within 45 degrees of `direction`: level, when
/// `direction` is up (what objects stand on and up_direction chooses from).
bool faces_within_45_degrees(const Plane& plane, const Eigen::Vector3d& camera, const Eigen::Vector3d& direction);

/// The configured up, else the normal of the largest plane within 45 degrees of the camera's own
/// up (as up_direction); none when no plane is (up_direction then falls back to the largest).
std::optional<Eigen::Vector3d> level_up(const std::optional<Eigen::Vector3d>& configured, const std::vector<Plane>& planes,
                                        const Pose& T_world_camera);

}  // namespace scenewatch::pipeline
