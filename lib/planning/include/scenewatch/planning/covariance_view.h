#pragma once
/// The seed's planner as a NextBestView measure: an object's points with their observation
/// histories (observation_history.h) become per-point covariances (depth_point_covariance), and
/// plan_covariance_view puts the camera on the request's sphere. Stateless functions: thread safe.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/planning/covariance_planner.h"

namespace scenewatch::planning {

/// The measure names of the seed's planner: "covariance" (rule 3.23, the seed's default),
/// "covariance_321", "covariance_322"; nullopt for any other name.
std::optional<WeightRule> parse_covariance_measure(const std::string& name);
/// The measure name of a rule ("covariance" for 3.23).
const char* covariance_measure_name(WeightRule rule);
/// Every measure name NextBestView accepts, comma separated (for error messages and help).
std::string all_measure_names();

struct CovarianceViewRequest {
  std::vector<Eigen::Vector3d> points_world;                 ///< the object's points and its box's hypotheses
  std::vector<std::vector<Eigen::Vector3d>> observers_world; ///< per point: the camera centres that observed it
  std::size_t box_hypotheses = 0;   ///< how many of the points are box_surface_samples (for `why`)
  SensorModel sensor;               ///< the noise of the observations
  double focal_px = 525.0;          ///< the observing cameras' focal length (lateral noise)
  double prior_sigma_m = 0.05;      ///< a point nobody observed (depth_point_covariance's prior)
  WeightRule rule = WeightRule::kAllAxesLambda;
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();  ///< the sphere's centre: the target's
  double radius_m = 0.7;
  Eigen::Vector3d up_world = Eigen::Vector3d::UnitZ();
  /// The cap constraint: the camera within this angle of up (none: the whole sphere). When the
  /// sphere's minimum lies outside, the cap's own minimum is searched on a 1-degree grid of it.
  std::optional<double> max_polar_deg;
};

/// Checks the request; the message names the field.
Status validate(const CovarianceViewRequest& request);

struct CovarianceViewAnswer {
  CovarianceView view;
  std::size_t points = 0;     ///< points planned for
  std::size_t observed = 0;   ///< of them, those some keyframe observed
  std::string why;            ///< the rule, the counts, the sphere case, the angle from up
  bool capped = false;        ///< the sphere's minimum lay outside the cap: the cap's grid minimum instead
};

/// The seed's planned view for the request.
Result<CovarianceViewAnswer> covariance_next_view(const CovarianceViewRequest& request);

}  // namespace scenewatch::planning
