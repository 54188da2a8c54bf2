#pragma once
// The transforms of a recording's /tf and /tf_static, looked up at a time: T_target_source by
// chaining the edges on the path between two frames. A /tf edge is interpolated between the two
// samples around the time (linear in translation, slerp in rotation), or taken from the nearest
// sample within `tolerance_s` of either end; a /tf_static edge holds at all times. NOT thread safe.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/io/bag/messages.h"

namespace scenewatch::io::bag {

class TfTree {
 public:
  void add(const StampedTransform& t, bool is_static);
  /// Drops the /tf samples older than `stamp_s` except the newest of them (a live stream's buffer).
  void forget_before(double stamp_s);
  bool empty() const { return edges_.empty(); }
  bool has_frame(const std::string& frame) const;
  /// The root above `frame` (following parents); `frame` itself when it has none.
  std::string root_of(const std::string& frame) const;
  /// T_target_source at `stamp_s`; the error says which link is missing, or at what times it exists.
  Result<Pose> lookup(const std::string& target, const std::string& source, double stamp_s, double tolerance_s) const;

 private:
  struct Edge {
    std::string parent, child;
    bool is_static = false;
    std::vector<std::pair<double, Pose>> samples;  ///< T_parent_child by time, sorted after sort()
    bool sorted = true;
  };
  Result<Pose> at(const Edge& e, double stamp_s, double tolerance_s) const;

  std::vector<Edge> edges_;
  std::map<std::string, std::size_t> edge_of_child_;  ///< each frame has one parent (TF's rule)
};

}  // namespace scenewatch::io::bag
