#pragma once
// Checks an OctoMap file (.ot, or .bt) before OctoMap reads it. OctoMap reads the node stream
// recursively and follows each node's child flags with no depth limit and no check that the
// stream has not ended: a damaged file (a flipped flag bit, a cut) recurses until the stack
// overflows, which ends the daemon while it loads its model (found by fuzz_model_loader). The
// check walks the same stream with the tree's depth bound (16 levels below the root) and refuses
// what OctoMap could not have written.
#include <filesystem>

#include "scenewatch/core/result.h"

namespace scenewatch::background {

/// OK when the file's header is OctoMap's, it holds an OcTree or a ColorOcTree with a positive
/// finite resolution, and its nodes are complete and at most 16 levels deep; otherwise
/// kInvalidArgument naming the file and the fault.
Status check_octree_file(const std::filesystem::path& path);

}  // namespace scenewatch::background
