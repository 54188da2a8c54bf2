// The scene snapshot after a frame (compose_snapshot.h).
#include "compose_snapshot.h"

namespace scenewatch::pipeline {

std::shared_ptr<SceneSnapshot> compose_snapshot(std::uint64_t frames, const std::vector<Plane>& planes,
                                                const ObjectTracker& tracker, const ForegroundStage& foreground,
                                                const std::optional<Eigen::Vector3d>& configured_up,
                                                const Pose& T_world_camera, double last_stamp_s,
                                                std::vector<PendingChangeSeen> pending) {
  auto s = std::make_shared<SceneSnapshot>();
  s->frames_processed = frames;
  s->planes = planes;
  s->objects = tracker.objects();
  for (auto& o : foreground.tracker().objects()) s->objects.push_back(std::move(o));
  s->hands = foreground.hands();
  for (const auto& o : tracker.objects()) {
    if (auto p = tracker.points(o.id)) s->points[o.id] = std::move(p);
  }
  for (const auto& o : foreground.tracker().objects()) {
    if (auto model = foreground.tracker().model(o.id)) {
      auto p = std::make_shared<std::vector<Eigen::Vector3d>>();
      for (const auto& q : model->points) p->push_back(o.foreground->T_world_object * q.getVector3fMap().cast<double>());
      s->points[o.id] = std::move(p);
    }
  }
  s->up_world = up_direction(configured_up, planes, T_world_camera);
  s->camera_world = T_world_camera.translation();
  s->last_stamp_s = last_stamp_s;
  s->pending = std::move(pending);
  return s;
}

}  // namespace scenewatch::pipeline
