#include "scenewatch/ontology/grasp.h"

#include <cmath>

#include <Eigen/Geometry>

namespace scenewatch::ontology {

std::vector<GraspPose> grasp_poses(const ObjectClass& c, const ShapeFit& fit, const Eigen::Vector3d& sensor) {
  std::vector<GraspPose> out;
  const Eigen::Vector3d up = fit.axis.normalized();
  // Horizontal direction from the sensor to the object: the side grasp's approach.
  Eigen::Vector3d towards = fit.center - sensor;
  towards -= towards.dot(up) * up;
  if (towards.norm() < 1e-6) towards = up.unitOrthogonal();
  towards.normalize();
  const Eigen::Vector3d box_y = up.cross(fit.x_axis);
  const double h = 0.5 * fit.height_m;
  auto radius_at = [&](double fraction) { return fit.bottom_radius_m + fraction * (fit.top_radius_m - fit.bottom_radius_m); };
  for (const GraspDefinition& g : c.grasps) {
    GraspPose p;
    p.name = g.name;
    p.kind = g.kind;
    switch (g.kind) {
      case GraspKind::kSide:
        p.position = fit.center + (-h + g.height_fraction * fit.height_m) * up;
        if (fit.shape == ClassShape::kBox) {
          // Close across the shorter edge, approach along the longer one, from the sensor's side.
          p.closing = fit.x_axis;
          p.approach = box_y.dot(towards) >= 0 ? box_y : Eigen::Vector3d(-box_y);
          p.width_m = fit.size_m.x();
        } else {
          p.approach = towards;
          p.closing = up.cross(towards).normalized();
          p.width_m = fit.shape == ClassShape::kSphere ? 2 * fit.radius_m : 2 * radius_at(g.height_fraction);
          if (fit.shape == ClassShape::kSphere) p.position = fit.center;
        }
        break;
      case GraspKind::kRim:
        // The rim point nearest the sensor; the fingers straddle the wall.
        p.position = fit.center + h * up - fit.top_radius_m * towards;
        p.approach = -up;
        p.closing = towards;
        p.width_m = 0.01;
        break;
      case GraspKind::kTop:
        p.approach = -up;
        if (fit.shape == ClassShape::kBox) {
          p.position = fit.center + h * up;
          p.closing = fit.x_axis;
          p.width_m = fit.size_m.x();
        } else if (fit.shape == ClassShape::kSphere) {
          p.position = fit.center + fit.radius_m * up;
          p.closing = up.cross(towards).normalized();
          p.width_m = 2 * fit.radius_m;
        } else {
          p.position = fit.center + h * up;
          p.closing = up.cross(towards).normalized();
          p.width_m = 2 * fit.top_radius_m;
        }
        break;
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace scenewatch::ontology
