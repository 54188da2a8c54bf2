// The seed's closed-form planner (D5.1 section 3.1.2.5) against brute-force sampling of the
// sphere, and its degenerate inputs.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "scenewatch/planning/candidates.h"
#include "scenewatch/planning/covariance_planner.h"

namespace scenewatch::planning {
namespace {

// The smallest f over `count` nearly uniform points of the sphere: the oracle.
double brute_force_minimum(const PlaneQuadratic& f, const Eigen::Vector3d& m, double r, int count) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& d : fibonacci_directions(count)) best = std::min(best, f(m + r * d));
  return best;
}

Eigen::Matrix3d random_covariance(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d M;
  for (int i = 0; i < 9; ++i) M(i) = n(rng);
  return 1e-4 * (M * M.transpose() + 0.01 * Eigen::Matrix3d::Identity());
}

struct Problem {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix3d> covariances;
};

Problem random_problem(std::mt19937_64& rng, int count) {
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  Problem p;
  for (int i = 0; i < count; ++i) {
    p.points.emplace_back(u(rng), u(rng), u(rng));
    p.covariances.push_back(random_covariance(rng));
  }
  return p;
}

void expect_on_sphere(const SphereMinimum& s, const Eigen::Vector3d& m, double r) {
  EXPECT_TRUE(s.x_world.allFinite());
  EXPECT_NEAR((s.x_world - m).norm(), r, 1e-9 * r);
}

TEST(CovariancePlanner, AgreesWithBruteForceSamplingOfTheSphere) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (WeightRule rule : {WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda, WeightRule::kAllAxesLambda}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Problem p = random_problem(rng, 1 + trial * 5);
      const Eigen::Vector3d m(u(rng), u(rng), u(rng));
      const double r = 0.5 + trial * 0.05;
      const PlaneQuadratic f = plane_quadratic(p.points, p.covariances, rule);
      const SphereMinimum s = minimize_on_sphere(f, m, r);
      expect_on_sphere(s, m, r);
      const double brute = brute_force_minimum(f, m, r, 200000);
      // Never worse than any sample; the samples (about 0.5 degrees apart) come within a small
      // fraction of the range of f over the sphere.
      const double spread = std::abs(brute_force_minimum(PlaneQuadratic{-f.A, -f.b, -f.c}, m, r, 2000)) + std::abs(brute);
      EXPECT_LE(s.value, brute + 1e-12 * spread) << to_string(rule) << " trial " << trial;
      EXPECT_GE(s.value, brute - 1e-3 * spread) << to_string(rule) << " trial " << trial;
    }
  }
}

TEST(CovariancePlanner, RuleAllAxesIsTheSumOfTheCovariances) {
  // Eq. (3.24): with w_ij = lambda_ij, A = sum P; the shortcut must equal the sum over the planes.
  std::mt19937_64 rng(3);
  const Problem p = random_problem(rng, 30);
  PlaneQuadratic planes;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(p.covariances[i]);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d n = eig.eigenvectors().col(j);
      const double w = eig.eigenvalues()(j), d = n.dot(p.points[i]);
      planes.A += w * n * n.transpose();
      planes.b += w * d * n;
      planes.c += w * d * d;
    }
  }
  const PlaneQuadratic f = plane_quadratic(p.points, p.covariances, WeightRule::kAllAxesLambda);
  EXPECT_LT((f.A - planes.A).norm(), 1e-12);
  EXPECT_LT((f.b - planes.b).norm(), 1e-12);
  EXPECT_NEAR(f.c, planes.c, 1e-12);
}

TEST(CovariancePlanner, IsotropicCovariancesGiveTheSphereNearestThePoints) {
  // All P = s^2 I: f = s^2 sum |x - y_i|^2, smallest at the sphere point towards the points' mean.
  std::vector<Eigen::Vector3d> points{{0.3, 0.1, 0.0}, {0.5, -0.1, 0.1}, {0.4, 0.0, -0.1}};
  std::vector<Eigen::Matrix3d> cov(points.size(), 1e-4 * Eigen::Matrix3d::Identity());
  const Eigen::Vector3d mean = (points[0] + points[1] + points[2]) / 3.0;
  for (WeightRule rule : {WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda, WeightRule::kAllAxesLambda}) {
    const PlaneQuadratic f = plane_quadratic(points, cov, rule);
    const SphereMinimum s = minimize_on_sphere(f, Eigen::Vector3d::Zero(), 1.0);
    expect_on_sphere(s, Eigen::Vector3d::Zero(), 1.0);
    EXPECT_LE(s.value, brute_force_minimum(f, Eigen::Vector3d::Zero(), 1.0, 100000) + 1e-12) << to_string(rule);
    if (rule == WeightRule::kAllAxesLambda) {
      EXPECT_LT((s.x_world - mean.normalized()).norm(), 1e-9);
    }
  }
}

TEST(CovariancePlanner, HardCaseWhenBPrimeIsOrthogonalToTheFirstEigenvector) {
  // A = diag(1, 2, 3), b' = (0, 0.1, 0.1): the solution without E_1 has length 0.11 < r, so
  // mu = lambda_1 and the rest of the length goes along e_x (either sign is optimal).
  PlaneQuadratic f;
  f.A = Eigen::Vector3d(1, 2, 3).asDiagonal();
  f.b = Eigen::Vector3d(0, 0.1, 0.1);
  const SphereMinimum s = minimize_on_sphere(f, Eigen::Vector3d::Zero(), 1.0, Eigen::Vector3d::UnitX());
  EXPECT_EQ(s.kind, SphereCase::kHardCase);
  expect_on_sphere(s, Eigen::Vector3d::Zero(), 1.0);
  EXPECT_NEAR(s.mu, 1.0, 1e-12);
  EXPECT_NEAR(s.x_world.y(), 0.1, 1e-12);
  EXPECT_NEAR(s.x_world.z(), 0.05, 1e-12);
  EXPECT_GT(s.x_world.x(), 0.0);  // the preferred side
  EXPECT_LE(s.value, brute_force_minimum(f, Eigen::Vector3d::Zero(), 1.0, 200000) + 1e-12);
  // The other side is as good.
  EXPECT_NEAR(f(Eigen::Vector3d(-s.x_world.x(), s.x_world.y(), s.x_world.z())), s.value, 1e-12);

  // b' orthogonal to e_x again but long: a solution with mu < lambda_1 exists and bisection finds it.
  f.b = Eigen::Vector3d(0, 5, 8);
  const SphereMinimum t = minimize_on_sphere(f, Eigen::Vector3d::Zero(), 1.0);
  EXPECT_EQ(t.kind, SphereCase::kBisection);
  expect_on_sphere(t, Eigen::Vector3d::Zero(), 1.0);
  EXPECT_LT(t.mu, 1.0);
  EXPECT_NEAR(t.x_world.x(), 0.0, 1e-9);
  EXPECT_LE(t.value, brute_force_minimum(f, Eigen::Vector3d::Zero(), 1.0, 200000) + 1e-12);
}

TEST(CovariancePlanner, NearlyOrthogonalBPrimeStaysOnTheSphere) {
  PlaneQuadratic f;
  f.A = Eigen::Vector3d(1, 2, 3).asDiagonal();
  for (double eps : {1e-6, 1e-9, 1e-13, 1e-16}) {
    f.b = Eigen::Vector3d(eps, 0.1, 0.1);
    const SphereMinimum s = minimize_on_sphere(f, Eigen::Vector3d::Zero(), 1.0);
    expect_on_sphere(s, Eigen::Vector3d::Zero(), 1.0);
    EXPECT_LE(s.value, brute_force_minimum(f, Eigen::Vector3d::Zero(), 1.0, 100000) + 1e-9) << eps;
  }
}

TEST(CovariancePlanner, SinglePoint) {
  // One point elongated along x: the planes of rule (3.21)/(3.22) hold every camera with x = 0.3
  // (the point's x), so the camera goes to where that plane meets the sphere.
  const std::vector<Eigen::Vector3d> point{{0.3, 0.0, 0.0}};
  const std::vector<Eigen::Matrix3d> cov{Eigen::Vector3d(4e-4, 1e-4, 1e-5).asDiagonal()};
  for (WeightRule rule : {WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda}) {
    const CovarianceView v = plan_covariance_view(point, cov, rule, Eigen::Vector3d::Zero(), 1.0);
    expect_on_sphere(v.minimum, Eigen::Vector3d::Zero(), 1.0);
    EXPECT_EQ(v.minimum.kind, SphereCase::kHardCase) << to_string(rule);
    EXPECT_NEAR(v.minimum.x_world.x(), 0.3, 1e-6) << to_string(rule);
    EXPECT_LT((v.look_at_world - point[0]).norm(), 1e-12);
    // The camera looks at the point.
    const Eigen::Vector3d dir = (point[0] - v.T_world_camera.translation()).normalized();
    EXPECT_GT(dir.dot(v.T_world_camera.linear().col(2)), 1.0 - 1e-12);
  }
  // Rule (3.23) also weighs the second axis (y): of the circle near x = 0.3 it keeps y = 0, so the
  // camera looks along z, the point's best-known axis. Hard case again (b' has no z component):
  // x = b_x / (lambda_x - lambda_z) = 1.2e-4 / 3.9e-4.
  const CovarianceView all = plan_covariance_view(point, cov, WeightRule::kAllAxesLambda, Eigen::Vector3d::Zero(), 1.0);
  expect_on_sphere(all.minimum, Eigen::Vector3d::Zero(), 1.0);
  EXPECT_NEAR(all.minimum.x_world.x(), 1.2 / 3.9, 1e-6);
  EXPECT_NEAR(all.minimum.x_world.y(), 0.0, 1e-6);
  EXPECT_LE(all.minimum.value,
            brute_force_minimum(plane_quadratic(point, cov, WeightRule::kAllAxesLambda), Eigen::Vector3d::Zero(), 1.0, 200000) + 1e-15);

  // A single isotropic point at the sphere's centre: f is constant; the preferred direction wins.
  const std::vector<Eigen::Vector3d> centre{{0, 0, 0}};
  const std::vector<Eigen::Matrix3d> iso{1e-4 * Eigen::Matrix3d::Identity()};
  const SphereMinimum s = minimize_on_sphere(plane_quadratic(centre, iso, WeightRule::kAllAxesLambda), Eigen::Vector3d::Zero(),
                                             2.0, Eigen::Vector3d::UnitY());
  EXPECT_EQ(s.kind, SphereCase::kAnyPoint);
  EXPECT_LT((s.x_world - Eigen::Vector3d(0, 2, 0)).norm(), 1e-12);
}

TEST(CovariancePlanner, DepthCovarianceFromTheSensorModel) {
  // One observation from 1 m: sigma along the ray is the axial noise, across it the lateral.
  SensorModel sensor;
  const Eigen::Vector3d p(0, 0, 1);
  const Eigen::Matrix3d P = depth_point_covariance(p, {Eigen::Vector3d::Zero()}, sensor, 525.0, 10.0);
  const double axial = sensor.sigma_z(1.0), lateral = 1.0 * sensor.lateral_px / 525.0;
  EXPECT_NEAR(std::sqrt(P(2, 2)), axial, 1e-3 * axial);
  EXPECT_NEAR(std::sqrt(P(0, 0)), lateral, 1e-3 * lateral);
  // A second view at right angles shrinks the axial uncertainty of the first to the lateral of the second.
  const Eigen::Matrix3d Q = depth_point_covariance(p, {Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 1)}, sensor, 525.0, 10.0);
  EXPECT_LT(Q(2, 2), 0.5 * P(2, 2));
}

TEST(Candidates, ConstraintsGiveValidPosesLookingAtTheTarget) {
  const Eigen::Vector3d target(0.1, 0.2, 0.8);
  ViewConstraint c;
  c.center_world = target;
  for (ConstraintKind kind : {ConstraintKind::kSphere, ConstraintKind::kShell, ConstraintKind::kCap}) {
    c.kind = kind;
    c.radius_min_m = 0.4;
    auto poses = candidate_poses(c, target);
    ASSERT_TRUE(poses) << poses.error().message;
    ASSERT_EQ(poses->size(), 64u);
    for (const Pose& T : *poses) {
      EXPECT_TRUE(validate_rigid(T.matrix(), 1e-9));
      const Eigen::Vector3d d = T.translation() - target;
      EXPECT_LE(d.norm(), c.radius_max_m + 1e-12);
      EXPECT_GE(d.norm(), (kind == ConstraintKind::kShell ? c.radius_min_m : c.radius_max_m) - 1e-12);
      EXPECT_GT((-d.normalized()).dot(T.linear().col(2)), 1.0 - 1e-12);
      if (kind == ConstraintKind::kCap) {
        EXPECT_GE(d.normalized().z(), std::cos(c.max_polar_deg * M_PI / 180) - 1e-12);
      }
    }
  }
  c.kind = ConstraintKind::kShell;
  c.radius_min_m = 2.0;
  EXPECT_FALSE(candidate_poses(c, target));
  c.kind = ConstraintKind::kList;
  EXPECT_FALSE(candidate_poses(c, target));
}

}  // namespace
}  // namespace scenewatch::planning
