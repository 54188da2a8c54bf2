// Remembered support planes: a cheap check of the last frame's planes before a new RANSAC search.
#include "plane_memory.h"

#include <cmath>

namespace scenewatch::foreground {
namespace {

/// A remembered plane explains the frame while its patches keep this share of their points.
constexpr double kPlaneKeepFraction = 0.8;
/// Planes are searched for again after this many frames however well they explain the frame:
/// a plane that came into view (the floor behind a person who left) is found within this.
constexpr int kPlaneMemoryFrames = 30;

/// The remembered planes on this frame, in the order they were found (each takes its inliers from
/// the points the next one sees, as the search does); empty when one of them no longer holds.
std::vector<SupportPlane> check_remembered(const std::vector<Eigen::Vector3f>& points,
                                           const std::vector<std::uint8_t>& valid, int width, int height,
                                           const SupportPlaneConfig& config, std::vector<std::uint8_t>* on_plane,
                                           const PlaneMemory& memory) {
  on_plane->assign(points.size(), 0);
  std::vector<int> remaining;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (valid[i]) remaining.push_back(static_cast<int>(i));
  }
  const std::size_t total = remaining.size();
  const std::size_t min_inliers = min_plane_inliers(config, total);
  std::vector<SupportPlane> planes;
  for (const SupportPlane& remembered : memory.planes) {
    std::vector<int> inliers, outliers;
    for (int i : remaining) {
      (std::abs(remembered.distance(points[i])) < config.tolerance_at(points[i].z()) ? inliers : outliers).push_back(i);
    }
    remaining.swap(outliers);
    const std::size_t needed = std::max(min_inliers, static_cast<std::size_t>(kPlaneKeepFraction * remembered.inliers));
    const std::size_t kept = keep_large_patches(points, inliers, width, height, config, total, needed, on_plane);
    if (kept == 0) return {};
    SupportPlane plane = remembered;
    plane.inliers = kept;
    planes.push_back(plane);
  }
  return planes;
}

}  // namespace

std::vector<SupportPlane> find_support_planes(const std::vector<Eigen::Vector3f>& points,
                                              const std::vector<std::uint8_t>& valid, int width, int height,
                                              const SupportPlaneConfig& config, std::vector<std::uint8_t>* on_plane,
                                              PlaneMemory* memory) {
  if (!memory) return find_support_planes(points, valid, width, height, config, on_plane);
  if (!memory->planes.empty() && memory->frames_since_search >= 0 && memory->frames_since_search < kPlaneMemoryFrames) {
    std::vector<SupportPlane> planes = check_remembered(points, valid, width, height, config, on_plane, *memory);
    if (!planes.empty()) {
      ++memory->frames_since_search;
      return planes;
    }
  }
  std::vector<SupportPlane> planes = find_support_planes(points, valid, width, height, config, on_plane);
  memory->planes = planes;
  memory->frames_since_search = 0;
  ++memory->searches;
  return planes;
}

}  // namespace scenewatch::foreground
