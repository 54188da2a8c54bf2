// The only translation unit with CGAL templates (compile time on 2 cores): CGAL 5.5's
// Shape_detection::Efficient_RANSAC over a vector of (point, normal) pairs, as in CGAL's example
// Shape_detection/efficient_RANSAC_basic.cpp.
#include "efficient_ransac.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

namespace scenewatch::ontology::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// The third element is the point's position in the caller's vector: the detection reorders its
// input in place (Efficient_RANSAC::preprocess swaps points into random subsets), so the indices
// of assigned points are positions in the reordered vector.
using PointWithNormal = std::tuple<Kernel::Point_3, Kernel::Vector_3, std::size_t>;
using PointVector = std::vector<PointWithNormal>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, PointWithNormal>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, PointWithNormal>;
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
                       Kernel::Vector_3(normals[i].x(), normals[i].y(), normals[i].z()), i);
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
      // Not -d() n: after its final least-squares update, CGAL 5.5's Plane keeps the d of the
      // unnormalized Plane_3 beside the normalized normal (Plane.h, update()). The inliers'
      // centroid lies on the fitted plane.
      p.direction = eigen(plane->plane_normal()).normalized();
      p.point.setZero();
      for (const std::size_t i : shape->indices_of_assigned_points()) p.point += points[std::get<2>(input[i])];
      p.point /= static_cast<double>(std::max<std::size_t>(1, shape->indices_of_assigned_points().size()));
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
    for (const std::size_t i : shape->indices_of_assigned_points()) p.indices.push_back(static_cast<int>(std::get<2>(input[i])));
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace scenewatch::ontology::detail
