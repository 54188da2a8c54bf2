// NextBestView's target for a tracked object: its completed surface when a class fits, its box
// otherwise (object_view_request.h).
#include "scenewatch/pipeline/object_view_request.h"

#include <algorithm>
#include <cstdio>
#include <optional>

namespace scenewatch::pipeline {

namespace {

// The up of the plane the object stands on (towards the camera), as the describer takes it;
// none for an object in a hand or on no plane of the snapshot: all its sides may be seen.
std::optional<Eigen::Vector3d> standing_up(const SceneSnapshot& snapshot, const TrackedObject& object) {
  if (object.foreground) return std::nullopt;
  for (const auto& plane : snapshot.planes) {
    if (plane.id == object.cluster.plane_id) return plane.normal_towards(snapshot.camera_world);
  }
  return std::nullopt;
}

}  // namespace

Result<ObjectViewRequest> object_view_request(WorkingMemory& memory, std::uint64_t object_id,
                                              const ontology::ClassCatalog* classes, const DescribedCallback& on_described) {
  const auto snapshot = memory.snapshot();
  const auto object = std::find_if(snapshot->objects.begin(), snapshot->objects.end(),
                                   [&](const TrackedObject& o) { return o.id == object_id; });
  if (object == snapshot->objects.end()) return not_found("object_id: no tracked object " + std::to_string(object_id));
  const Aabb box = object->cluster.box.aabb();
  ObjectViewRequest out;
  out.request = planning::complete_object_request(box);
  if (!classes) {
    out.target_description = "the object's box: the daemon has no object classes to complete it by";
    return out;
  }
  const auto info = memory.describe_object(*snapshot, object_id, *classes, on_described);
  if (!info) {
    out.target_description = "the object's box: it has no points kept to describe it by";
    return out;
  }
  if (info->completed_surface_world.empty() || !info->primitive) {
    out.target_description = "the object's box: no class fits it (" + info->class_name + "), so its unseen side is not known";
    return out;
  }
  const double voxel = memory.config().background.resolution_m;
  const auto up = standing_up(*snapshot, *object);
  std::vector<Eigen::Vector3d> surface =
      up ? planning::above_lowest_layer(info->completed_surface_world, *up, voxel) : info->completed_surface_world;
  if (surface.empty()) {
    out.target_description = "the object's box: its completed " + info->class_name + " is no taller than a voxel";
    return out;
  }
  char text[256];
  std::snprintf(text, sizeof text, "the completed surface of a %s (%s, its unseen side included): %zu points%s", info->class_name.c_str(),
                ontology::to_string(info->primitive->shape), surface.size(),
                up ? ", less the face it stands on" : ", all sides (it stands on no plane)");
  out.target_description = text;
  out.request = planning::complete_surface_request(box, std::move(surface));
  return out;
}

}  // namespace scenewatch::pipeline
