#pragma once
// Frames named on the command line:
//   FILE.pcd | FILE.ply     one cloud in its camera frame (identity pose); organized clouds get
//                           intrinsics recovered from their points unless given
//   SEQDIR                  every frame of a sequence folder (with its poses and intrinsics)
//   SEQDIR:N                frame N (0-based) of a sequence
//   SEQDIR/frame-NNNNNN     the frame of that name
//   SEQDIR:A-B              frames A to B inclusive
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::cli {

/// How many frames a spec names (opens sequences, reads no images).
Result<std::size_t> count_frames(const std::string& spec, const io::SequenceOptions& sequence = {});

/// Loads the frames of a spec in order, calling `each` for every one (stops at its error).
/// `intrinsics` replaces the recovered intrinsics of cloud files; `sequence` says how sequence
/// folders are read (depth scale). Frames a TUM folder leaves out are counted on stderr.
Status for_each_frame(const std::string& spec, const std::optional<Intrinsics>& intrinsics,
                      const std::function<Status(Frame)>& each, const io::SequenceOptions& sequence = {});

/// Exactly one frame (a cloud file or one frame of a sequence); a spec naming several is an error
/// that shows how to name one.
Result<Frame> load_one_frame(const std::string& spec, const io::SequenceOptions& sequence = {});

/// The frames of a sequence folder a spec names: the opened sequence and the indices first..last
/// (inclusive, within the sequence).
struct SequenceSpan {
  std::string folder;
  io::Sequence sequence;
  std::size_t first = 0, last = 0;
};
/// The sequence frames `spec` names (SEQDIR, SEQDIR:N, SEQDIR:A-B, SEQDIR/frame-NNNNNN); nothing
/// when it names a cloud file; an error naming the spec when it names neither.
Result<std::optional<SequenceSpan>> sequence_span(const std::string& spec, const io::SequenceOptions& sequence = {});

/// The SequenceOptions of a command's --depth-scale (unset: the folder's or the layout's unit).
io::SequenceOptions sequence_options(const std::optional<double>& depth_scale_m);

}  // namespace scenewatch::cli
