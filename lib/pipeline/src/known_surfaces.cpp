// Known surfaces of described objects (known_surfaces.h).
#include "known_surfaces.h"

#include <algorithm>

namespace scenewatch::pipeline {

void KnownSurfaces::set(std::uint64_t object_id, const Eigen::Vector3d& centroid_world, surprise::KnownSurface surface) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (surface.points_world.empty()) {
    known_.erase(object_id);
    return;
  }
  known_[object_id] = {centroid_world, std::make_shared<const surprise::KnownSurface>(std::move(surface))};
}

std::vector<std::shared_ptr<const surprise::KnownSurface>> KnownSurfaces::current(const SceneSnapshot& scene) {
  constexpr double kMovedM = 0.02;
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::shared_ptr<const surprise::KnownSurface>> out;
  for (auto it = known_.begin(); it != known_.end();) {
    const auto object = std::find_if(scene.objects.begin(), scene.objects.end(),
                                     [&](const TrackedObject& o) { return o.id == it->first; });
    if (object == scene.objects.end() || (object->cluster.centroid - it->second.centroid_world).norm() > kMovedM) {
      it = known_.erase(it);
      continue;
    }
    out.push_back(it->second.surface);
    ++it;
  }
  return out;
}

void KnownSurfaces::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  known_.clear();
}

}  // namespace scenewatch::pipeline
