// The ontology's facade for one object: fit, classify, grasp, complete.
#include "scenewatch/ontology/describe.h"

#include <map>

#include "scenewatch/ontology/completion.h"

namespace scenewatch::ontology {

Result<ObjectDescription> describe(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& up_in,
                                   const ClassLibrary& library, const Eigen::Vector3d& sensor, const DescribeConfig& config) {
  if (!(up_in.allFinite() && up_in.norm() > 0)) return invalid_argument("describe: the up vector is zero or not finite");
  if (!(config.completion_spacing_m >= 0)) return invalid_argument("describe: completion_spacing_m must be >= 0");
  const Eigen::Vector3d up = up_in.normalized();
  auto fitted = fit_object(cloud, indices, config.fit, up, sensor);
  if (!fitted) return fitted.error();
  ObjectDescription out;
  out.fit = std::move(*fitted);
  if (out.fit.best >= 0) out.best_primitive = out.fit.shapes[static_cast<std::size_t>(out.fit.best)];
  const auto& points = out.fit.sample_points;
  const auto& normals = out.fit.sample_normals;
  // One fit per shape, shared by the classes of that shape.
  std::map<ClassShape, std::optional<ShapeFit>> shapes;
  const ClassMatch* best = nullptr;
  const ClassMatch* best_refused = nullptr;
  out.candidates.reserve(library.classes().size());
  for (const ObjectClass& c : library.classes()) {
    auto it = shapes.find(c.shape);
    if (it == shapes.end()) it = shapes.emplace(c.shape, fit_shape(c.shape, points, normals, out.fit, up)).first;
    if (!it->second) {
      ClassMatch m;
      m.class_name = c.name;
      m.reason = std::string("no ") + to_string(c.shape) + " could be fitted";
      out.candidates.push_back(std::move(m));
      continue;
    }
    out.candidates.push_back(match_class(c, *it->second, points, normals));
  }
  for (const ClassMatch& m : out.candidates) {
    if (m.accepted && (!best || m.score > best->score)) best = &m;
    if (!m.accepted && m.score > 0 && (!best_refused || m.score > best_refused->score)) best_refused = &m;
  }
  if (!best) {
    if (best_refused) out.primitive = best_refused->fit;
    return out;
  }
  const ObjectClass& c = *library.find(best->class_name);
  out.class_name = c.name;
  out.score = best->score;
  out.primitive = best->fit;
  out.grasps = grasp_poses(c, best->fit, sensor);
  if (config.completion_spacing_m > 0) {
    const bool open = c.top == ClassTop::kOpen || (c.top == ClassTop::kAny && best->fit.inner_fraction >= kOpenTopMinInnerFraction);
    out.completed_points = complete_surface(best->fit, config.completion_spacing_m, open);
  }
  return out;
}

Result<ObjectDescription> describe(const std::vector<Eigen::Vector3d>& points_world, const Eigen::Vector3d& up_world,
                                   const ClassLibrary& library, const Eigen::Vector3d& sensor_world,
                                   const DescribeConfig& config) {
  Cloud cloud;
  cloud.points.reserve(points_world.size());
  std::vector<int> indices;
  indices.reserve(points_world.size());
  for (const auto& p : points_world) {
    PointT q;
    q.getVector3fMap() = p.cast<float>();
    indices.push_back(static_cast<int>(cloud.points.size()));
    cloud.points.push_back(q);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.points.size());
  cloud.height = 1;
  cloud.is_dense = false;
  return describe(cloud, indices, up_world, library, sensor_world, config);
}

}  // namespace scenewatch::ontology
