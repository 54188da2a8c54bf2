#include "scenewatch/planning/covariance_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenewatch/core/look_at.h"
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

// The point of the cap {polar <= max_polar_deg} that minimises f: a grid of 1 degree in polar
// angle and azimuth, which holds every local minimum of the quadratic within a degree. Used only
// when the sphere's exact minimum lies outside the cap.
Eigen::Vector3d minimum_on_cap(const PlaneQuadratic& f, const Eigen::Vector3d& center, double radius,
                               const Eigen::Vector3d& up, double max_polar_deg) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d e1 = u.unitOrthogonal(), e2 = u.cross(e1);
  Eigen::Vector3d best = center + radius * u;
  double best_value = f(best);
  const int polar_steps = static_cast<int>(std::ceil(max_polar_deg));
  for (int i = 1; i <= polar_steps; ++i) {
    const double theta = std::min(static_cast<double>(i), max_polar_deg) * M_PI / 180.0;
    for (int k = 0; k < 360; ++k) {
      const double phi = k * M_PI / 180.0;
      const Eigen::Vector3d x =
          center + radius * (std::cos(theta) * u + std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2));
      const double value = f(x);
      if (value < best_value) best_value = value, best = x;
    }
  }
  return best;
}

Status validate(const CovarianceViewRequest& r) {
  if (r.points_world.empty()) return invalid_argument("points: the object has no points to plan for");
  if (r.observers_world.size() != r.points_world.size()) return invalid_argument("observers: one list per point");
  if (!(r.radius_m > 0.0 && std::isfinite(r.radius_m))) return invalid_argument("radius_m: must be > 0");
  if (!(r.focal_px > 0.0 && std::isfinite(r.focal_px))) return invalid_argument("focal_px: must be > 0");
  if (!(r.prior_sigma_m > 0.0 && std::isfinite(r.prior_sigma_m))) return invalid_argument("prior_sigma_m: must be > 0");
  if (!r.center_world.allFinite()) return invalid_argument("center: not finite");
  if (!(r.up_world.norm() > 0.0 && r.up_world.allFinite())) return invalid_argument("up: must be a non-zero vector");
  if (r.max_polar_deg && !(*r.max_polar_deg > 0.0 && *r.max_polar_deg <= 180.0)) {
    return invalid_argument("max_polar_deg: must be in (0, 180] degrees");
  }
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
  const auto polar_of = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d dir = (x - r.center_world).normalized();
    return std::acos(std::clamp(dir.dot(r.up_world.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
  };
  if (r.max_polar_deg && polar_of(answer.view.minimum.x_world) > *r.max_polar_deg) {
    const PlaneQuadratic f = plane_quadratic(r.points_world, covariances, r.rule);
    answer.view.minimum.x_world = minimum_on_cap(f, r.center_world, r.radius_m, r.up_world, *r.max_polar_deg);
    answer.view.minimum.value = f(answer.view.minimum.x_world);
    answer.view.T_world_camera = look_at(answer.view.minimum.x_world, answer.view.look_at_world, r.up_world);
    answer.capped = true;
  }
  const double polar_deg = polar_of(answer.view.minimum.x_world);
  char why[400];
  std::snprintf(why, sizeof why,
                "%s (seed eq. %s, %s): %zu points (%zu of the box's surface), %zu observed by keyframes, the rest at the "
                "prior; sphere %.2f m, case %s (%d bisection steps)%s; %.0f degrees from up",
                covariance_measure_name(r.rule), equation(r.rule), to_string(r.rule), answer.points, r.box_hypotheses, answer.observed,
                r.radius_m, to_string(answer.view.minimum.kind), answer.view.minimum.iterations,
                answer.capped ? ", below the cap: the cap's minimum" : "", polar_deg);
  answer.why = why;
  return answer;
}

}  // namespace scenewatch::planning
