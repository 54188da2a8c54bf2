#pragma once
/// The seed's closed-form view planner (D5.1 section 3.1.2.5): each point's covariance axes give
/// planes through the point on which a camera would best shrink that axis; the camera goes to the
/// place on a sphere that minimises the weighted squared distances to all planes (eq. 3.9), found
/// from the secular equation (3.18) by bisection between the bounds of (3.19)-(3.20). Stateless
/// functions: thread safe.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::planning {

/// How the planes of one point are weighted.
enum class WeightRule {
  kMajorAxisUnit,     ///< eq. (3.21): the largest axis only, weight 1
  kMajorAxisLambda,   ///< eq. (3.22): the largest axis only, weight its eigenvalue
  kAllAxesLambda,     ///< eq. (3.23): every axis, weight its eigenvalue (A = sum of covariances)
};
const char* to_string(WeightRule rule);

/// The quadratic f(x) = x^T A x - 2 b^T x + c of eq. (3.9)-(3.11).
struct PlaneQuadratic {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double c = 0.0;
  double operator()(const Eigen::Vector3d& x) const { return x.dot(A * x) - 2.0 * b.dot(x) + c; }
};

/// Builds the quadratic from points and their 3x3 covariances (same length) under a weight rule.
/// Rule (3.23) needs no eigen-decomposition: A = sum P_i, b = sum P_i y_i, c = sum y_i^T P_i y_i.
PlaneQuadratic plane_quadratic(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Matrix3d>& covariances, WeightRule rule);

/// How the minimum on the sphere was found.
enum class SphereCase {
  kBisection,   ///< mu < lambda_1 from the secular equation, bracketed by (3.19)-(3.20)
  kHardCase,    ///< b' (nearly) orthogonal to the eigenvectors of lambda_1: mu = lambda_1
  kAnyPoint,    ///< f is constant on the sphere (A isotropic and b' = 0): `preferred` direction
};
const char* to_string(SphereCase kind);

struct SphereMinimum {
  Eigen::Vector3d x_world = Eigen::Vector3d::Zero();  ///< on the sphere
  double value = 0.0;                                 ///< f(x)
  double mu = 0.0;                                    ///< the Lagrange multiplier of eq. (3.15)
  SphereCase kind = SphereCase::kBisection;
  int iterations = 0;                                 ///< bisection steps
};

/// Minimises f on the sphere |x - center| = radius (radius > 0). Where several points are
/// optimal (hard case, constant f) the one nearest `center + radius * preferred_direction` is
/// returned.
SphereMinimum minimize_on_sphere(const PlaneQuadratic& f, const Eigen::Vector3d& center, double radius,
                                 const Eigen::Vector3d& preferred_direction = Eigen::Vector3d::UnitZ());

/// The points' weighted centre, each point weighted by the sum of its planes' weights.
Eigen::Vector3d weighted_centre(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Matrix3d>& covariances, WeightRule rule);

/// The planned view: where the camera goes on the sphere, looking at the weighted centre.
struct CovarianceView {
  Pose T_world_camera = Pose::Identity();
  Eigen::Vector3d look_at_world = Eigen::Vector3d::Zero();
  SphereMinimum minimum;
};

/// The seed's planner end to end. `points` and `covariances` have the same length (>= 1).
CovarianceView plan_covariance_view(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Eigen::Matrix3d>& covariances, WeightRule rule,
                                    const Eigen::Vector3d& sphere_center, double sphere_radius,
                                    const Eigen::Vector3d& up_world = Eigen::Vector3d::UnitZ());

/// A point's 3x3 position covariance after depth observations from the given camera centres
/// (information added per observation): axial noise sensor.sigma_z(range) along each ray, lateral
/// noise sensor.lateral_px at focal length `focal_px` across it. No observation: `prior_sigma_m`
/// isotropic. Observations from one place shrink only along and across that ray.
Eigen::Matrix3d depth_point_covariance(const Eigen::Vector3d& point_world,
                                       const std::vector<Eigen::Vector3d>& camera_centers_world,
                                       const SensorModel& sensor, double focal_px, double prior_sigma_m = 0.05);

}  // namespace scenewatch::planning
