#pragma once
/// Writes a simulated sequence in the layout io::open_sequence reads (see io/sequence.h):
/// frame-NNNNNN.{color,depth,label}.png, frame-NNNNNN.pose.txt, trajectory.txt (TUM),
/// camera-intrinsics.txt and ground_truth.json. Every format is written by io's writers.
#include <filesystem>
#include <string>
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/sim/ground_truth.h"

namespace scenewatch::sim {

/// "frame-000042" for index 42.
std::string frame_name(int index);

/// Writes one sequence folder. NOT thread safe.
class SequenceWriter {
 public:
  /// Creates the folder (and parents) and deletes the frame files, trajectory, intrinsics and
  /// ground truth a previous run left in it, so that no stale frame survives.
  static Result<SequenceWriter> create(const std::filesystem::path& dir);

  /// Writes the images and the 4x4 pose of one frame and remembers its stamp and pose.
  Status write_frame(int index, double stamp_s, const ColorImage& color, const DepthImage& depth,
                     const LabelImage& labels, const Pose& T_world_camera);

  /// Writes trajectory.txt, camera-intrinsics.txt and ground_truth.json.
  Status finish(const Intrinsics& K, const SequenceTruth& truth);

  /// The folder.
  const std::filesystem::path& dir() const { return dir_; }

 private:
  explicit SequenceWriter(std::filesystem::path dir) : dir_(std::move(dir)) {}
  std::filesystem::path dir_;
  std::vector<std::pair<double, Pose>> poses_;
};

}  // namespace scenewatch::sim
