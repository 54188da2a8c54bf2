#include "scenewatch/core/scene_json.h"

namespace scenewatch {
using nlohmann::json;

namespace {
json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json dof_names(const DofFlags& f) {
  json names = json::array();
  for (int k = 0; k < kDofCount; ++k)
    if (f[static_cast<std::size_t>(k)]) names.push_back(to_string(static_cast<Dof>(k)));
  return names;
}
}  // namespace

json to_json(const ForegroundState& s) {
  json handlings = json::array();
  for (const auto& h : s.handlings) {
    handlings.push_back({{"start_s", h.start_s}, {"end_s", h.end_s}, {"range", std::vector<double>(h.range.begin(), h.range.end())},
                         {"moved", dof_names(h.moved)}});
  }
  const Eigen::Matrix4d& m = s.T_world_object.matrix();
  return {{"T_world_object", std::vector<double>(m.data(), m.data() + 16)}, {"free", dof_names(s.free)},
          {"handlings", handlings}, {"promoted_s", s.promoted_s}, {"model_points", s.model_points},
          {"in_hand", s.in_hand}, {"visible", s.visible}};
}

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
  json j = {{"id", o.id}, {"plane_id", c.plane_id}, {"centroid", vec(c.centroid)}, {"box", to_json(c.box)},
            {"point_count", c.point_count}, {"mean_rgb", {c.mean_rgb.x(), c.mean_rgb.y(), c.mean_rgb.z()}},
            {"rgb_covariance", std::vector<float>(c.rgb_covariance.data(), c.rgb_covariance.data() + 9)},
            {"first_seen_s", o.first_seen_s}, {"last_seen_s", o.last_seen_s}, {"observations", o.observations},
            {"supported_by", o.supported_by}};
  if (o.foreground) j["foreground"] = to_json(*o.foreground);
  return j;
}

}  // namespace scenewatch
