// The only translation unit with CGAL templates (compile time on 2 cores): CGAL 5.5's
// Shape_detection::Efficient_RANSAC over a vector of (point, normal) pairs, as in CGAL's example
// Shape_detection/efficient_RANSAC_basic.cpp.
#include "efficient_ransac.h"

#include <algorithm>
#include <cmath>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

namespace scenewatch::ontology::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using PointWithNormal = std::pair<Kernel::Point_3, Kernel::Vector_3>;
using PointVector = std::vector<PointWithNormal>;
using PointMap = CGAL::First_of_pair_property_map<PointWithNormal>;
using NormalMap = CGAL::Second_of_pair_property_map<PointWithNormal>;
using Traits = CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, PointVector, PointMap, NormalMap>;
using EfficientRansac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
using CgalPlane = CGAL::Shape_detection::Plane<Traits>;
using CgalCylinder = CGAL::Shape_detection::Cylinder<Traits>;
using CgalSphere = CGAL::Shape_detection::Sphere<Traits>;
using CgalCone = CGAL::Shape_detection::Cone<Traits>;

Eigen::Vector3d eigen(const Kernel::Point_3& p) { return {p.x(), p.y(), p.z()}; }
Eigen::Vector3d eigen(const Kernel::Vector_3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

std::vector<Primitive> detect_shapes(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals, const FitConfig& config) {
  PointVector input;
  input.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    input.emplace_back(Kernel::Point_3(points[i].x(), points[i].y(), points[i].z()),
                       Kernel::Vector_3(normals[i].x(), normals[i].y(), normals[i].z()));
  }
  // Reproducible: the detection draws from CGAL's (thread-local) default generator.
  CGAL::get_default_random() = CGAL::Random(config.seed);

  EfficientRansac ransac;
  ransac.set_input(input);
  if (config.detect_plane) ransac.add_shape_factory<CgalPlane>();
  if (config.detect_cylinder) ransac.add_shape_factory<CgalCylinder>();
  if (config.detect_sphere) ransac.add_shape_factory<CgalSphere>();
  if (config.detect_cone) ransac.add_shape_factory<CgalCone>();

  EfficientRansac::Parameters parameters;
  parameters.probability = config.probability;
  parameters.min_points = std::max<std::size_t>(
      static_cast<std::size_t>(config.min_points),
      static_cast<std::size_t>(std::lround(config.min_shape_fraction * static_cast<double>(points.size()))));
  parameters.epsilon = config.epsilon_m;
  parameters.cluster_epsilon = config.cluster_epsilon_m;
  parameters.normal_threshold = config.normal_threshold;
  ransac.detect(parameters);

  std::vector<Primitive> out;
  for (const auto& shape : ransac.shapes()) {
    Primitive p;
    if (const auto* plane = dynamic_cast<const CgalPlane*>(shape.get())) {
      p.kind = PrimitiveKind::kPlane;
      p.direction = eigen(plane->plane_normal()).normalized();
      p.point = -plane->d() * eigen(plane->plane_normal()) / eigen(plane->plane_normal()).squaredNorm();
    } else if (const auto* cylinder = dynamic_cast<const CgalCylinder*>(shape.get())) {
      p.kind = PrimitiveKind::kCylinder;
      p.point = eigen(cylinder->axis().point(0));
      p.direction = eigen(cylinder->axis().to_vector()).normalized();
      p.radius_m = cylinder->radius();
    } else if (const auto* sphere = dynamic_cast<const CgalSphere*>(shape.get())) {
      p.kind = PrimitiveKind::kSphere;
      p.point = eigen(sphere->center());
      p.radius_m = sphere->radius();
    } else if (const auto* cone = dynamic_cast<const CgalCone*>(shape.get())) {
      p.kind = PrimitiveKind::kCone;
      p.point = eigen(cone->apex());
      p.direction = eigen(cone->axis()).normalized();
      p.half_angle_deg = cone->angle() * 180.0 / M_PI;
    } else {
      continue;  // a factory we did not add
    }
    const auto& assigned = shape->indices_of_assigned_points();
    p.indices.assign(assigned.begin(), assigned.end());
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace scenewatch::ontology::detail
