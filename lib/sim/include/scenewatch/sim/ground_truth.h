#pragma once
/// Exact ground truth of a simulated sequence (ground_truth.json) and of the changes between two
/// sequences (changes.json): object poses per frame, contacts, manipulations with the degrees of
/// freedom that moved (in the support plane's frame), and added / removed / moved objects.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/dof.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"
#include "scenewatch/sim/scenario.h"

namespace scenewatch::sim {

// The DoF vocabulary (Dof, DofVector, DofFlags, dof_delta) is scenewatch's, in core/dof.h.
using scenewatch::Dof;
using scenewatch::DofFlags;
using scenewatch::DofVector;
using scenewatch::dof_delta;
using scenewatch::kDofCount;

/// An object as the ground truth describes it (enough to evaluate its surface).
struct ObjectTruth {
  int id = 0;
  std::string name;
  std::uint16_t label = 0;
  Shape shape;
  bool transparent = false;
};

/// An object's pose in one frame.
struct ObjectPose {
  int id = 0;
  Pose T_world_object = Pose::Identity();
};

/// Ground truth of one frame.
struct FrameTruth {
  std::string name;                                ///< "frame-000000"
  double stamp_s = 0.0;
  Pose T_world_camera = Pose::Identity();          ///< the true pose (images were rendered with it)
  Pose T_world_camera_reported = Pose::Identity(); ///< the pose written to trajectory.txt / pose.txt
  std::optional<Pose> T_world_hand;
  std::vector<ObjectPose> objects;
  std::vector<int> held;
  std::vector<int> touched;
};

/// A run of frames in which the hand touches (or holds) an object; frames inclusive.
struct ContactInterval {
  int object_id = 0;
  int first_frame = 0;
  int last_frame = 0;
};

/// One grasp-to-release episode of an object.
struct Manipulation {
  int object_id = 0;
  int grasp_frame = 0;     ///< first frame in which the object is held
  int release_frame = -1;  ///< first frame in which it is no longer held; -1: held to the end
  DofVector dof_range{};   ///< max - min of dof_delta from the grasp over the episode
  DofFlags moved{};        ///< range above the thresholds
  DofFlags newly_moved{};  ///< moved, and frozen in every earlier manipulation of the object
};

/// A later manipulation that moves a DoF frozen so far: the seed's IMPLAUSIBILITY (section 3.3).
/// The first manipulation of an object is where its free DoFs are learnt and is never listed.
struct FrozenDofMotion {
  int object_id = 0;
  int manipulation = 0;     ///< index into SequenceTruth::manipulations
  std::vector<Dof> dofs;    ///< the frozen DoFs that moved
  int first_frame = 0;      ///< first frame in which one of them exceeds its threshold
};

/// Ground truth of one sequence.
struct SequenceTruth {
  std::string scenario;
  std::string phase;
  std::uint64_t seed = 0;
  Intrinsics intrinsics;
  Pose T_world_support = Pose::Identity();  ///< the table top's frame (z up)
  DofThresholds thresholds;
  std::vector<ObjectTruth> objects;
  std::vector<FrameTruth> frames;
  std::vector<ContactInterval> touched;     ///< filled by analyse_interactions
  std::vector<ContactInterval> held;
  std::vector<Manipulation> manipulations;
  std::vector<FrozenDofMotion> frozen_dof_motions;
};

/// Fills the contact intervals, manipulations and frozen-DoF motions from the frames.
void analyse_interactions(SequenceTruth* truth);

/// An object's placement on one side of a change.
struct PlacedObject {
  ObjectTruth object;
  Pose T_world_object = Pose::Identity();
};

/// An object that is in both sequences but elsewhere.
struct ObjectDisplacement {
  int id = 0;
  Pose T_world_before = Pose::Identity();  ///< in the last frame of the first sequence
  Pose T_world_after = Pose::Identity();   ///< in the first frame of the second
  Eigen::Vector3d translation_world_m = Eigen::Vector3d::Zero();
  double rotation_deg = 0.0;
  DofVector dof_delta{};                   ///< in the support frame
};

/// What changed from one sequence to the next.
struct ChangeTruth {
  std::string from, to;
  std::vector<PlacedObject> added;    ///< as placed in the first frame of `to`
  std::vector<PlacedObject> removed;  ///< as placed in the last frame of `from`
  std::vector<ObjectDisplacement> moved;
};

/// Compares the end of `before` with the start of `after`; a displacement counts as a move when
/// it exceeds the thresholds of `after`.
ChangeTruth compare_sequences(const SequenceTruth& before, const SequenceTruth& after);

/// Writes ground_truth.json (atomically: temporary file, then rename).
Status write_ground_truth(const std::filesystem::path& path, const SequenceTruth& truth);
/// Reads a ground_truth.json back; errors name the file and the key.
Result<SequenceTruth> read_ground_truth(const std::filesystem::path& path);

/// Writes changes.json for consecutive pairs of sequences of a scenario.
Status write_changes(const std::filesystem::path& path, const std::string& scenario,
                     const std::vector<ChangeTruth>& changes);
/// Reads a changes.json back.
Result<std::vector<ChangeTruth>> read_changes(const std::filesystem::path& path);

}  // namespace scenewatch::sim
