#include "scenewatch/pipeline/covariance_view_request.h"

#include <algorithm>
#include <string>

#include "scenewatch/planning/observation_history.h"

namespace scenewatch::pipeline {

namespace {

// The observing cameras' focal length: the keyframes' mean (they may come from several cameras).
double mean_focal_px(const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes, double otherwise) {
  double sum = 0.0;
  for (const auto& kf : keyframes) sum += 0.5 * (kf->intrinsics.fx + kf->intrinsics.fy);
  return keyframes.empty() ? otherwise : sum / static_cast<double>(keyframes.size());
}

}  // namespace

Result<planning::CovarianceViewRequest> covariance_view_request(const WorkingMemory& memory, std::uint64_t object_id,
                                                                planning::WeightRule rule, double radius_m) {
  const auto snapshot = memory.snapshot();
  const auto object = std::find_if(snapshot->objects.begin(), snapshot->objects.end(),
                                   [&](const TrackedObject& o) { return o.id == object_id; });
  if (object == snapshot->objects.end()) return not_found("object_id: no tracked object " + std::to_string(object_id));
  const auto points = snapshot->points.find(object_id);
  if (points == snapshot->points.end() || !points->second || points->second->empty()) {
    return not_found("object_id: object " + std::to_string(object_id) + " has no points kept");
  }
  const Config& config = memory.config();
  planning::DepthAgreement agreement;
  agreement.sensor = config.sensor;
  agreement.sigma_factor = config.change.sigma_factor;
  agreement.resolution_m = config.background.resolution_m;

  planning::CovarianceViewRequest r;
  r.points_world = *points->second;
  // The object's points were all seen; its unseen side exists only as the faces of its box.
  const auto faces = planning::box_surface_samples(object->cluster.box, snapshot->up_world, agreement.resolution_m);
  r.points_world.insert(r.points_world.end(), faces.begin(), faces.end());
  r.box_hypotheses = faces.size();
  const auto keyframes = memory.keyframes();
  r.observers_world = planning::observing_camera_centres(r.points_world, keyframes, agreement);
  r.sensor = config.sensor;
  r.focal_px = mean_focal_px(keyframes, r.focal_px);
  r.rule = rule;
  r.center_world = object->cluster.box.center;
  r.radius_m = radius_m;
  r.up_world = snapshot->up_world;
  return r;
}

}  // namespace scenewatch::pipeline
