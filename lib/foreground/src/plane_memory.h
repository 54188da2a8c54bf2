#pragma once
/// Support planes remembered from frame to frame: a table, a floor and a wall do not move in front
/// of a fixed camera, so the planes found in an earlier frame are checked against the new frame
/// (one pass over its points) and searched for again (support_plane.h's RANSAC) only when they no
/// longer explain it, or every `kPlaneMemoryFrames` frames. Private to the foreground module.
#include <cstdint>
#include <vector>

#include "support_plane.h"

namespace scenewatch::foreground {

/// What one plane search keeps for the next frames. NOT thread safe: one per frame stream.
struct PlaneMemory {
  std::vector<SupportPlane> planes;  ///< as last searched for, each with its patch points then
  int frames_since_search = -1;      ///< -1: nothing remembered
  std::size_t searches = 0;          ///< RANSAC searches made (the frames whose planes did not hold)
  void clear() { *this = PlaneMemory{}; }  // the search count too
};

/// find_support_planes with a memory: when every remembered plane still has large patches of at
/// least kPlaneKeepFraction of the points it had when found (an arm over the table takes some),
/// the remembered planes are the answer; otherwise the planes are searched for and remembered.
/// With memory == nullptr this is find_support_planes.
std::vector<SupportPlane> find_support_planes(const std::vector<Eigen::Vector3f>& points,
                                              const std::vector<std::uint8_t>& valid, int width, int height,
                                              const SupportPlaneConfig& config, std::vector<std::uint8_t>* on_plane,
                                              PlaneMemory* memory);

}  // namespace scenewatch::foreground
