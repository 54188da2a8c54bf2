#pragma once
/// describe(): everything the ontology says about one object: its class with a score (or
/// `unknown` with its best primitive), the class's primitive fitted to it, grasp poses and the
/// completed surface. This is the function GetObjects is meant to call per tracked object: give it
/// the object's points in the world frame, the support's normal (world up for objects standing on
/// a table) and the camera position; everything returned is in that same world frame.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/result.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/classify.h"
#include "scenewatch/ontology/fit.h"
#include "scenewatch/ontology/grasp.h"
#include "scenewatch/ontology/shape_fit.h"

namespace scenewatch::ontology {

/// The class name of an object no class accepts.
inline constexpr const char* kUnknownClass = "unknown";

struct DescribeConfig {
  FitConfig fit;                     ///< primitive fitting (fit_object)
  double completion_spacing_m = 0.004;  ///< spacing of the completed surface's points; 0: no completion
};

/// What describe() found.
struct ObjectDescription {
  std::string class_name = kUnknownClass;  ///< the best accepted class, or "unknown"
  double score = 0;                        ///< its score (ClassMatch::score), 0 for unknown
  /// The class's primitive fitted to the object; unknown: the best of the shapes fitted for the
  /// classes (the highest score), if any.
  std::optional<ShapeFit> primitive;
  /// The shape detection's primitive with the most points (reported for unknown objects; not a class).
  std::optional<Primitive> best_primitive;
  std::vector<ClassMatch> candidates;      ///< every class tried, in library order
  std::vector<GraspPose> grasps;           ///< the class's grasps on its primitive (none for unknown)
  /// The class's primitive's whole surface (the unseen side included, no sensor noise); empty for
  /// unknown or when completion_spacing_m is 0.
  std::vector<Eigen::Vector3d> completed_points;
  ObjectFit fit;                           ///< the primitive fitting behind it
};

/// Describes the object made of cloud[indices]. `up` is the support's unit normal, `sensor` the
/// camera position (it orients normals and picks the reachable side for grasps), both in the
/// cloud's frame. Errors: those of fit_object (too few points, an index outside the cloud).
/// Thread safe (as fit_object); `library` is only read.
Result<ObjectDescription> describe(const Cloud& cloud, const std::vector<int>& indices, const Eigen::Vector3d& up,
                                   const ClassLibrary& library, const Eigen::Vector3d& sensor = Eigen::Vector3d::Zero(),
                                   const DescribeConfig& config = {});

/// The same for the object's points given directly (e.g. a tracked object's points in the world
/// frame with up_world = the table's normal and sensor_world = the camera's position).
Result<ObjectDescription> describe(const std::vector<Eigen::Vector3d>& points_world, const Eigen::Vector3d& up_world,
                                   const ClassLibrary& library, const Eigen::Vector3d& sensor_world,
                                   const DescribeConfig& config = {});

}  // namespace scenewatch::ontology
