#pragma once
// Surfaces of described objects that the mesh may lack (WorkingMemory::set_known_surface), kept
// while each object stays where it was described. Thread safe.
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/pipeline/scene_snapshot.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::pipeline {

class KnownSurfaces {
 public:
  /// A newer surface of an object replaces its older one; an empty one removes it.
  void set(std::uint64_t object_id, const Eigen::Vector3d& centroid_world, surprise::KnownSurface surface);
  /// The surfaces of objects still in `scene` within 2 cm of where they were described; the others
  /// are forgotten.
  std::vector<std::shared_ptr<const surprise::KnownSurface>> current(const SceneSnapshot& scene);
  void clear();

 private:
  struct Known {
    Eigen::Vector3d centroid_world;
    std::shared_ptr<const surprise::KnownSurface> surface;
  };
  std::mutex mutex_;
  std::map<std::uint64_t, Known> known_;
};

}  // namespace scenewatch::pipeline
