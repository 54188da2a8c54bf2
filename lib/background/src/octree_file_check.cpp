#include "octree_file_check.h"

#include <octomap/AbstractOcTree.h>

#include <bitset>
#include <cmath>
#include <fstream>
#include <string>

#include "scenewatch/core/files.h"

namespace scenewatch::background {
namespace fs = std::filesystem;

namespace {

/// OctoMap's own header reader (protected in AbstractOcTree), so that the check starts where
/// OctoMap's reading of the nodes will.
struct HeaderReader : octomap::AbstractOcTree {
  using octomap::AbstractOcTree::readHeader;
};

/// Levels below the root: OctoMap's trees are 16 deep (keys of 16 bits).
constexpr unsigned kTreeDepth = 16;

/// Walks a node stream without building a tree; `fault` says what is wrong when it returns false.
class NodeWalk {
 public:
  NodeWalk(std::istream& in, std::size_t data_bytes) : in_(in), data_bytes_(data_bytes) {}

  /// .ot: each node is its data, then one byte with a flag per existing child; the children follow.
  bool text_node(unsigned depth) {
    char flags = 0;
    if (!skip(data_bytes_) || !in_.get(flags)) return cut_short();
    const std::bitset<8> children(static_cast<unsigned char>(flags));
    if (children.any() && depth == kTreeDepth) return too_deep();
    for (int i = 0; i < 8; ++i) {
      if (children[i] && !text_node(depth + 1)) return false;
    }
    return true;
  }

  /// .bt: each inner node is two bytes, two bits per child (00 none, 01 and 10 a leaf, 11 a node
  /// of its own, which follows).
  bool binary_node(unsigned depth) {
    char low = 0, high = 0;
    if (!in_.get(low) || !in_.get(high)) return cut_short();
    const unsigned codes = static_cast<unsigned char>(low) | (static_cast<unsigned>(static_cast<unsigned char>(high)) << 8);
    for (int i = 0; i < 8; ++i) {
      if (((codes >> (2 * i)) & 3u) != 3u) continue;
      if (depth + 1 >= kTreeDepth) return too_deep();
      if (!binary_node(depth + 1)) return false;
    }
    return true;
  }

  const std::string& fault() const { return fault_; }

 private:
  bool skip(std::size_t n) {
    char sink[16];
    return in_.read(sink, static_cast<std::streamsize>(n)) && in_.gcount() == static_cast<std::streamsize>(n);
  }
  bool cut_short() {
    fault_ = "its nodes end before the tree does (cut short or damaged)";
    return false;
  }
  bool too_deep() {
    fault_ = "its nodes go deeper than an octree's " + std::to_string(kTreeDepth) + " levels (damaged)";
    return false;
  }

  std::istream& in_;
  std::size_t data_bytes_;
  std::string fault_;
};

}  // namespace

Status check_octree_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error(quoted(path) + ": cannot open for reading");
  std::string first;
  std::getline(in, first);
  const bool binary = first.rfind("# Octomap OcTree binary file", 0) == 0;
  if (!binary && first.rfind("# Octomap OcTree file", 0) != 0) {
    return invalid_argument(quoted(path) + ": not an OctoMap file (its first line is not OctoMap's)");
  }
  std::string id;
  unsigned size = 0;
  double resolution = 0;
  if (!HeaderReader::readHeader(in, id, size, resolution)) {
    return invalid_argument(quoted(path) + ": its OctoMap header is incomplete or invalid (id, size, res, data)");
  }
  if (!std::isfinite(resolution) || resolution <= 0) {
    return invalid_argument(quoted(path) + ": the map's resolution is not a positive number");
  }
  // Node data in an .ot: a float of log-odds, and a colour (three bytes) in a ColorOcTree.
  std::size_t data_bytes = sizeof(float);
  if (id == "ColorOcTree") {
    data_bytes += 3;
  } else if (id != "OcTree") {
    return invalid_argument(quoted(path) + ": holds a " + id + ", not an occupancy tree");
  }
  NodeWalk walk(in, data_bytes);
  if (size > 0 && !(binary ? walk.binary_node(0) : walk.text_node(0))) {
    return invalid_argument(quoted(path) + ": " + walk.fault());
  }
  return {};
}

}  // namespace scenewatch::background
