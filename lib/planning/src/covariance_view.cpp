#include "scenewatch/planning/covariance_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenewatch/planning/volumetric.h"

namespace scenewatch::planning {

namespace {

constexpr WeightRule kRules[] = {WeightRule::kAllAxesLambda, WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda};

const char* equation(WeightRule rule) {
  switch (rule) {
    case WeightRule::kMajorAxisUnit: return "3.21";
    case WeightRule::kMajorAxisLambda: return "3.22";
    case WeightRule::kAllAxesLambda: return "3.23";
  }
  return "3.23";
}

}  // namespace

const char* covariance_measure_name(WeightRule rule) {
  switch (rule) {
    case WeightRule::kMajorAxisUnit: return "covariance_321";
    case WeightRule::kMajorAxisLambda: return "covariance_322";
    case WeightRule::kAllAxesLambda: return "covariance";
  }
  return "covariance";
}

std::optional<WeightRule> parse_covariance_measure(const std::string& name) {
  for (WeightRule r : kRules) {
    if (name == covariance_measure_name(r)) return r;
  }
  return std::nullopt;
}

std::string all_measure_names() {
  std::string names;
  for (Measure m : {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware, Measure::kVisible}) {
    names += std::string(to_string(m)) + ", ";
  }
  for (WeightRule r : kRules) names += std::string(covariance_measure_name(r)) + (r == kRules[2] ? "" : ", ");
  return names;
}

Status validate(const CovarianceViewRequest& r) {
  if (r.points_world.empty()) return invalid_argument("points: the object has no points to plan for");
  if (r.observers_world.size() != r.points_world.size()) return invalid_argument("observers: one list per point");
  if (!(r.radius_m > 0.0 && std::isfinite(r.radius_m))) return invalid_argument("radius_m: must be > 0");
  if (!(r.focal_px > 0.0 && std::isfinite(r.focal_px))) return invalid_argument("focal_px: must be > 0");
  if (!(r.prior_sigma_m > 0.0 && std::isfinite(r.prior_sigma_m))) return invalid_argument("prior_sigma_m: must be > 0");
  if (!r.center_world.allFinite()) return invalid_argument("center: not finite");
  if (!(r.up_world.norm() > 0.0 && r.up_world.allFinite())) return invalid_argument("up: must be a non-zero vector");
  return {};
}

Result<CovarianceViewAnswer> covariance_next_view(const CovarianceViewRequest& r) {
  if (auto st = validate(r); !st) return st.error();
  CovarianceViewAnswer answer;
  answer.points = r.points_world.size();
  std::vector<Eigen::Matrix3d> covariances;
  covariances.reserve(r.points_world.size());
  for (std::size_t i = 0; i < r.points_world.size(); ++i) {
    covariances.push_back(depth_point_covariance(r.points_world[i], r.observers_world[i], r.sensor, r.focal_px, r.prior_sigma_m));
    answer.observed += r.observers_world[i].empty() ? 0 : 1;
  }
  answer.view = plan_covariance_view(r.points_world, covariances, r.rule, r.center_world, r.radius_m, r.up_world);
  const Eigen::Vector3d dir = (answer.view.T_world_camera.translation() - r.center_world).normalized();
  const double polar_deg = std::acos(std::clamp(dir.dot(r.up_world.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
  char why[320];
  std::snprintf(why, sizeof why,
                "%s (seed eq. %s, %s): %zu points (%zu of the box's surface), %zu observed by keyframes, the rest at the "
                "prior; sphere %.2f m, case %s (%d bisection steps); %.0f degrees from up",
                covariance_measure_name(r.rule), equation(r.rule), to_string(r.rule), answer.points, r.box_hypotheses, answer.observed,
                r.radius_m, to_string(answer.view.minimum.kind), answer.view.minimum.iterations, polar_deg);
  answer.why = why;
  return answer;
}

}  // namespace scenewatch::planning
