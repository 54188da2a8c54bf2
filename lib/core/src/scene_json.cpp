#include "scenewatch/core/scene_json.h"

namespace scenewatch {
using nlohmann::json;

namespace {
json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
}  // namespace

json to_json(const OrientedBox& b) {
  const Eigen::Quaterniond& q = b.rotation;
  return {{"center", vec(b.center)}, {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}, {"extents", vec(b.extents)}};
}

json to_json(const Plane& p) {
  json hull = json::array();
  for (const auto& h : p.hull) hull.push_back(vec(h));
  return {{"id", p.id}, {"normal", vec(p.normal)}, {"d", p.d}, {"hull", hull}, {"area_m2", p.area_m2},
          {"inlier_count", p.inlier_count}, {"centroid", vec(p.centroid)}};
}

json to_json(const TrackedObject& o) {
  const ObjectCluster& c = o.cluster;
  return {{"id", o.id}, {"plane_id", c.plane_id}, {"centroid", vec(c.centroid)}, {"box", to_json(c.box)},
          {"point_count", c.point_count}, {"mean_rgb", {c.mean_rgb.x(), c.mean_rgb.y(), c.mean_rgb.z()}},
          {"first_seen_s", o.first_seen_s}, {"last_seen_s", o.last_seen_s}, {"observations", o.observations},
          {"supported_by", o.supported_by}};
}

}  // namespace scenewatch
