#pragma once
/// RGB-D sequences on disk, in one of two layouts, told apart by their files:
///
/// Frames (7-Scenes, the simulator, hrt1): one file set per frame, by name
///   frame-NNNNNN.color.png (or .color.jpg), frame-NNNNNN.depth.png, camera-intrinsics.txt (3x3 K)
///   and poses either as frame-NNNNNN.pose.txt (4x4 camera-to-world) or as one TUM trajectory file
///   (trajectory.txt or groundtruth.txt) with one line per frame, in order. Depth in millimetres.
///   Optional frame-NNNNNN.label.png files hold instance labels (the simulator writes them).
///
/// TUM RGB-D benchmark, as published: rgb.txt and depth.txt ("timestamp filename" per line, the
///   images under rgb/ and depth/), groundtruth.txt ("timestamp tx ty tz qx qy qz qw",
///   T_world_camera, usually at a higher rate than the images). Each colour image is paired with the
///   depth image nearest in time, each depth image used once (TUM's associate.py), and the pair with
///   the ground-truth pose nearest to the depth's stamp; a pair farther apart than
///   SequenceOptions::max_time_difference_s is skipped and counted. Without groundtruth.txt the
///   frames have no pose. Depth in units of 1/5000 m. Intrinsics: camera-intrinsics.txt when
///   present, else TUM's default (fx = fy = 525, cx = 319.5, cy = 239.5).
///
/// In both layouts a depth-scale.txt beside camera-intrinsics.txt (one number: metres per depth
/// unit) overrides the layout's depth unit, and SequenceOptions::depth_scale_m overrides both.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// How a sequence folder is read.
struct SequenceOptions {
  /// Metres per depth unit; unset: depth-scale.txt, else the layout's unit (mm; TUM 1/5000 m).
  std::optional<double> depth_scale_m;
  /// TUM layout: colour, depth and pose further apart in time than this are not one frame.
  double max_time_difference_s = 0.02;
};

enum class SequenceLayout { kFrames, kTum };

struct SequenceEntry {
  std::string name;  ///< "frame-000150"; in the TUM layout the colour file's stem ("1305031102.175304")
  std::filesystem::path color, depth;
  std::optional<Pose> T_world_camera;
  double stamp_s = 0.0;
};

struct Sequence {
  std::filesystem::path dir;
  SequenceLayout layout = SequenceLayout::kFrames;
  Intrinsics intrinsics;  ///< width/height filled from the first frame
  double depth_scale_m = 1e-3;  ///< metres per depth unit
  std::vector<SequenceEntry> frames;
  /// TUM layout: colour images left out because no depth image, or no pose, was near enough in time.
  std::size_t skipped_without_depth = 0, skipped_without_pose = 0;
};

/// True when the path is a folder that looks like a sequence: frame-*.color.png or .color.jpg
/// files, or a TUM rgb.txt.
bool is_sequence_dir(const std::filesystem::path& path);

/// Lists the frames of a sequence folder and reads intrinsics, depth scale and poses (but no
/// images). Errors name the file, and the line for a text file that does not parse.
Result<Sequence> open_sequence(const std::filesystem::path& dir, const SequenceOptions& options = {});

/// What reading left out, for the user ("12 colour images without a depth image within 0.02 s
/// skipped"); empty when nothing was.
std::string skipped_summary(const Sequence& seq, const SequenceOptions& options = {});

/// Loads one frame of an opened sequence into an organized cloud with pose and intrinsics.
Result<Frame> load_sequence_frame(const Sequence& seq, std::size_t index);

/// Loads a single cloud file (.pcd/.ply) as a Frame without pose.
Result<Frame> load_cloud_frame(const std::filesystem::path& path);

}  // namespace scenewatch::io
