#pragma once
/// What moves during a phase: the hand along its keys, and every object it grasps, which follows
/// the hand rigidly from the grasp key to the release key. Also which objects the hand touches.
#include <optional>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/sim/hand.h"
#include "scenewatch/sim/scenario.h"

namespace scenewatch::sim {

/// The state of the scene at one time of a phase.
struct WorldState {
  std::vector<Pose> T_world_object;   ///< parallel to Animator::objects()
  std::optional<Pose> T_world_hand;   ///< none when the phase has no hand
  std::vector<int> held;              ///< ids of objects in the hand
  std::vector<int> touched;           ///< ids of objects the hand touches (held ones included)
};

/// Animates one phase. Immutable after creation: thread safe.
class Animator {
 public:
  /// Checks the hand's keys against the objects (grasp of an unknown id, release of an object that
  /// is not held, two objects at once) and precomputes the grasps.
  static Result<Animator> create(std::vector<SceneObject> objects, HandSpec hand, double touch_tolerance_m);

  /// The state at a (fractional) time in frames.
  WorldState state_at(double frame) const;

  /// The objects, with their poses at the start of the phase.
  const std::vector<SceneObject>& objects() const { return objects_; }
  /// The hand.
  const HandSpec& hand() const { return hand_; }
  /// The hand's capsules in the hand frame.
  const std::vector<HandPart>& hand_parts() const { return parts_; }

 private:
  struct Attachment {
    std::size_t object = 0;
    double grasp_frame = 0.0;
    double release_frame = 0.0;  ///< +inf while never released
    Pose T_hand_object = Pose::Identity();
  };
  Animator() = default;
  Pose object_pose(std::size_t index, double frame) const;

  std::vector<SceneObject> objects_;
  HandSpec hand_;
  std::vector<HandPart> parts_;
  std::vector<Attachment> attachments_;  ///< in time order
  double touch_tolerance_m_ = 0.01;
};

}  // namespace scenewatch::sim
