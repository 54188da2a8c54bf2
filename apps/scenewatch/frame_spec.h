#pragma once
// Frames named on the command line:
//   FILE.pcd | FILE.ply     one cloud in its camera frame (identity pose); organized clouds get
//                           intrinsics recovered from their points unless given
//   SEQDIR                  every frame of a sequence folder (with its poses and intrinsics)
//   SEQDIR:N                frame N (0-based) of a sequence
//   SEQDIR/frame-NNNNNN     the frame of that name
//   SEQDIR:A-B              frames A to B inclusive
//   BAG, BAG:N, BAG:A-B     the frames of a ROS bag (a .bag, .db3 or .mcap file, or a rosbag2 folder
//                           with metadata.yaml), all, the N-th or A to B (see scenewatch/io/bag.h)
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/io/bag.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::cli {

/// How the inputs of a command are read: sequence folders and bags.
struct InputOptions {
  io::SequenceOptions sequence;
  io::BagOptions bag;
  InputOptions() = default;
  /// Implicit: commands that take no bag flags pass their SequenceOptions.
  InputOptions(const io::SequenceOptions& s) : sequence(s) {}  // NOLINT(google-explicit-constructor)
};

/// How many frames a spec names (opens sequences, reads no images).
Result<std::size_t> count_frames(const std::string& spec, const InputOptions& inputs = {});

/// Loads the frames of a spec in order, calling `each` for every one (stops at its error).
/// `intrinsics` replaces the recovered intrinsics of cloud files; `sequence` says how sequence
/// folders are read (depth scale). Frames a TUM folder leaves out are counted on stderr.
Status for_each_frame(const std::string& spec, const std::optional<Intrinsics>& intrinsics,
                      const std::function<Status(Frame)>& each, const InputOptions& inputs = {});

/// Exactly one frame (a cloud file or one frame of a sequence); a spec naming several is an error
/// that shows how to name one.
Result<Frame> load_one_frame(const std::string& spec, const InputOptions& inputs = {});

/// The frames of a sequence folder or a bag a spec names: the opened sequence (or bag) and the
/// indices first..last (inclusive, within it).
struct SequenceSpan {
  std::string folder;                      ///< the folder or the bag, as named
  io::Sequence sequence;                   ///< a folder's frames (empty for a bag)
  std::shared_ptr<io::Recording> bag;      ///< a bag's frames; null for a folder
  std::size_t first = 0, last = 0;

  /// How a frame is named to the user: SEQDIR/frame-NNNNNN, or BAG:N.
  std::string frame_name(std::size_t index) const;
  /// Loads frame `index` (NOT thread safe for a bag).
  Result<Frame> load(std::size_t index) const;
  /// What opening left out ("3 colour images without depth skipped"); empty when nothing was.
  std::string skipped(const InputOptions& inputs) const;
};
/// The sequence or bag frames `spec` names (SEQDIR, SEQDIR:N, SEQDIR:A-B, SEQDIR/frame-NNNNNN,
/// BAG, BAG:N, BAG:A-B); nothing when it names a cloud file; an error naming the spec when it
/// names neither.
Result<std::optional<SequenceSpan>> sequence_span(const std::string& spec, const InputOptions& inputs = {});

/// The SequenceOptions of a command's --depth-scale (unset: the folder's or the layout's unit).
io::SequenceOptions sequence_options(const std::optional<double>& depth_scale_m);

}  // namespace scenewatch::cli
