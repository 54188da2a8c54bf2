#pragma once
/// Grasp poses: a class's grasp definitions placed on the object's fitted primitive.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/ontology/object_class.h"
#include "scenewatch/ontology/shape_fit.h"

namespace scenewatch::ontology {

/// A parallel-jaw grasp in the frame of the fitted primitive (the world frame for describe()).
struct GraspPose {
  std::string name;  ///< the definition's name
  GraspKind kind = GraspKind::kSide;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< between the fingertips
  Eigen::Vector3d approach = Eigen::Vector3d::UnitX(); ///< unit; the direction the gripper moves in
  Eigen::Vector3d closing = Eigen::Vector3d::UnitY();  ///< unit; the direction the fingers close along
  double width_m = 0;  ///< the opening needed: the object's width along `closing` (rim: the wall, 0.01)
};

/// The poses of `object_class.grasps` on `fit`. Side grasps approach horizontally from the side
/// facing `sensor` (the reachable side); rim and top grasps approach along -axis.
std::vector<GraspPose> grasp_poses(const ObjectClass& object_class, const ShapeFit& fit, const Eigen::Vector3d& sensor);

}  // namespace scenewatch::ontology
