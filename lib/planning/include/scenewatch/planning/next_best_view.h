#pragma once
/// The planning facade: candidate views from a constraint, each scored on the memory's map by a
/// volumetric measure, discounted by the cost of moving there, ranked, with the target's expected
/// coverage and a sentence saying why. Also the attention requests built on it: the view that
/// confirms or dismisses an event, and the view that completes an object's model.
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/planning/candidates.h"
#include "scenewatch/planning/volumetric.h"

namespace scenewatch::planning {

struct NextBestViewRequest {
  Aabb target_world;                  ///< what to see (an object's box, an event's box, the workspace)
  /// Narrows the target to a surface in its box (ViewScorer's surface_world): an object's
  /// completed primitive, its unseen side included. Empty: every voxel of the box counts.
  std::vector<Eigen::Vector3d> target_surface_world;
  ViewConstraint constraint;          ///< where the camera may go (centre: usually the target's)
  Measure measure = Measure::kRearSideEntropy;
  int n = 5;                          ///< how many views to return, best first
  Intrinsics intrinsics{525.0, 525.0, 319.5, 239.5, 640, 480};
  VolumetricConfig volumetric;
  std::optional<Pose> current_T_world_camera;  ///< where the camera is now (for the motion cost)
  /// Motion cost: score = gain * exp(-motion_cost_per_m * distance), Isler et al.'s discount.
  double motion_cost_per_m = 0.5;
};

/// Checks the request; the message names the field.
Status validate(const NextBestViewRequest& request);

struct RankedView {
  Pose T_world_camera = Pose::Identity();
  double score = 0.0;          ///< gain after the motion cost
  double motion_m = 0.0;       ///< distance from the current camera (0 without one)
  ViewGain gain;
  std::string why;             ///< one sentence: what the view would see
};

struct NextBestViewAnswer {
  std::vector<RankedView> views;       ///< best first, at most n
  std::size_t candidates = 0;          ///< candidates scored
  std::size_t target_voxels = 0;
  double coverage_now = 0.0;           ///< fraction of the target's voxels known now
  Measure measure = Measure::kRearSideEntropy;
  /// A target surface no candidate gains anything on (all its voxels known, or the unknown ones
  /// hidden from every candidate): the views were planned for the box instead, and the fields above
  /// are the box's. The surface's voxels and coverage then:
  bool planned_for_box = false;
  std::size_t surface_voxels = 0;
  double surface_coverage = 0.0;
};

/// The box of the map the planner needs: the target and every candidate position, with a margin.
/// Error for a bad request.
Result<Aabb> planning_region(const NextBestViewRequest& request);

/// Scores every candidate of the request on `grid` (which should cover planning_region()).
Result<NextBestViewAnswer> next_best_views(const background::DenseGrid& grid, const NextBestViewRequest& request);

/// Attention: the request that best confirms or dismisses a change in `event_box_world`: the
/// views that see most of the box (measure kVisible), the box grown by `margin_m` (a voxel or
/// two: the change's surface may lie on the box's border).
NextBestViewRequest confirm_event_request(const Aabb& event_box_world, double margin_m = 0.04);

/// Attention: the request that completes an object's model: the unseen side of its box, the
/// measure rear side entropy (unknown space behind the surface seen so far).
NextBestViewRequest complete_object_request(const Aabb& object_box_world, double margin_m = 0.02);

/// The points of an object's surface above its lowest layer of `layer_m` along `up`: the face it
/// stands on touches its support, and no view reaches it.
std::vector<Eigen::Vector3d> above_lowest_layer(const std::vector<Eigen::Vector3d>& surface_world, const Eigen::Vector3d& up,
                                                double layer_m);

/// The same for an object whose whole surface is known from its class (the ontology's completed
/// primitive, `surface_world`, the face it stands on left out): only the voxels of that surface
/// count, and the target box is the object's box and the surface's, grown by `margin_m`.
NextBestViewRequest complete_surface_request(const Aabb& object_box_world, std::vector<Eigen::Vector3d> surface_world,
                                             double margin_m = 0.02);

}  // namespace scenewatch::planning
