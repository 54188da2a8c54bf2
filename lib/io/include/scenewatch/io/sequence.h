#pragma once
/// RGB-D sequences on disk. A sequence is a folder holding
///   frame-NNNNNN.color.png (or .color.jpg), frame-NNNNNN.depth.png   (one pair per frame, by name)
///   camera-intrinsics.txt                           (3x3 K)
/// and poses either as frame-NNNNNN.pose.txt (4x4 camera-to-world, the 7-Scenes layout) or as
/// one TUM trajectory file (trajectory.txt or groundtruth.txt) with one line per frame, in order.
/// Optional frame-NNNNNN.label.png files hold instance labels (the simulator writes them).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

struct SequenceEntry {
  std::string name;  ///< "frame-000150"
  std::filesystem::path color, depth;
  std::optional<Pose> T_world_camera;
  double stamp_s = 0.0;
};

struct Sequence {
  std::filesystem::path dir;
  Intrinsics intrinsics;  ///< width/height filled from the first frame
  std::vector<SequenceEntry> frames;
};

/// True when the path is a folder that looks like a sequence (has *.color.png or *.color.jpg files).
bool is_sequence_dir(const std::filesystem::path& path);

/// Lists the frames of a sequence folder and reads intrinsics and poses (but no images).
Result<Sequence> open_sequence(const std::filesystem::path& dir);

/// Loads one frame of an opened sequence into an organized cloud with pose and intrinsics.
Result<Frame> load_sequence_frame(const Sequence& seq, std::size_t index);

/// Loads a single cloud file (.pcd/.ply) as a Frame without pose.
Result<Frame> load_cloud_frame(const std::filesystem::path& path);

}  // namespace scenewatch::io
