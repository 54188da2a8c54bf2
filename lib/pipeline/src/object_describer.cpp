// The ontology's descriptions of tracked objects, on request and cached (object_describer.h).
#include "object_describer.h"

#include <chrono>
#include <utility>

#include "scenewatch/ontology/describe.h"

namespace scenewatch::pipeline {

std::vector<std::shared_ptr<const ObjectClassInfo>> ObjectDescriber::describe(const SceneSnapshot& snapshot,
                                                                              const ontology::ClassCatalog& classes,
                                                                              const DescribedCallback& on_described) {
  std::vector<std::shared_ptr<const ObjectClassInfo>> out;
  out.reserve(snapshot.objects.size());
  for (const auto& object : snapshot.objects) out.push_back(describe(snapshot, object, classes, on_described));
  return out;
}

std::shared_ptr<const ObjectClassInfo> ObjectDescriber::describe_one(const SceneSnapshot& snapshot, std::uint64_t object_id,
                                                                     const ontology::ClassCatalog& classes,
                                                                     const DescribedCallback& on_described) {
  for (const auto& object : snapshot.objects) {
    if (object.id == object_id) return describe(snapshot, object, classes, on_described);
  }
  return nullptr;
}

void ObjectDescriber::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  described_.clear();
}

// Cached per object: described again only when it was seen again (new points) and its description
// is older than kDescribeAgainS.
std::shared_ptr<const ObjectClassInfo> ObjectDescriber::describe(const SceneSnapshot& snapshot, const TrackedObject& object,
                                                                 const ontology::ClassCatalog& classes,
                                                                 const DescribedCallback& on_described) {
  const std::uint64_t id = object.id;
  const auto points = snapshot.points.find(id);
  if (points == snapshot.points.end() || !points->second) return nullptr;
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  std::lock_guard<std::mutex> lock(mutex_);
  auto& cached = described_[id];
  const bool fresh = cached.points == points->second.get() || now - cached.at_s < kDescribeAgainS;
  if (!fresh || !cached.info) {
    ontology::DescribeConfig dc;  // the completed surface goes to the expected view, not to the caller
    // Up is the normal of the plane the object stands on, turned towards the camera.
    Eigen::Vector3d up = snapshot.up_world;
    for (const auto& plane : snapshot.planes) {
      if (plane.id != object.cluster.plane_id || object.foreground) continue;
      up = plane.normal_towards(snapshot.camera_world);
    }
    auto d = ontology::describe(*points->second, up, classes.library(), snapshot.camera_world, dc);
    auto info = std::make_shared<ObjectClassInfo>();  // an object that cannot be fitted is unknown
    if (d) {
      info->class_name = d->class_name;
      info->score = d->score;
      info->primitive = std::move(d->primitive);
      info->grasps = std::move(d->grasps);
      info->completed_surface_world = d->completed_points;
    }
    cached.info = info;
    cached.points = points->second.get();
    cached.at_s = now;
    if (on_described) on_described(object, *info);
    // The completed primitive predicts the object's unseen side in later frames' expected view
    // (none for unknown objects: that removes an earlier one).
    surprise::KnownSurface surface;
    if (d) surface.points_world = std::move(d->completed_points);
    surface.spacing_m = dc.completion_spacing_m;
    surface.rgb = object.cluster.mean_rgb;
    surface.rgb_covariance = object.cluster.rgb_covariance;
    known_.set(id, object.cluster.centroid, std::move(surface));
  }
  return cached.info;
}

}  // namespace scenewatch::pipeline
