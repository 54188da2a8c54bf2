// The seed's view planner, D5.1 section 3.1.2.5, eqs. (3.8)-(3.24). The minimisation of a
// quadratic on a sphere follows Hager (SIAM J. Optim. 2001), as the seed does: the global minimum
// has a multiplier mu <= lambda_1 (A - mu I positive semidefinite).
#include "scenewatch/planning/covariance_planner.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "scenewatch/planning/candidates.h"

namespace scenewatch::planning {

const char* to_string(WeightRule rule) {
  switch (rule) {
    case WeightRule::kMajorAxisUnit: return "major_unit";
    case WeightRule::kMajorAxisLambda: return "major_lambda";
    case WeightRule::kAllAxesLambda: return "all_lambda";
  }
  return "all_lambda";
}

const char* to_string(SphereCase kind) {
  switch (kind) {
    case SphereCase::kBisection: return "bisection";
    case SphereCase::kHardCase: return "hard_case";
    case SphereCase::kAnyPoint: return "any_point";
  }
  return "bisection";
}

namespace {

// The largest eigenvalue of a covariance and its axis (n_{i,1}, lambda_{i,1} of the seed).
void major_axis(const Eigen::Matrix3d& P, Eigen::Vector3d* axis, double* lambda) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(P);
  *axis = eig.eigenvectors().col(2);
  *lambda = std::max(0.0, eig.eigenvalues()(2));
}

// The weight of point i as a whole: the sum of its planes' weights under the rule.
double point_weight(const Eigen::Matrix3d& P, WeightRule rule) {
  switch (rule) {
    case WeightRule::kMajorAxisUnit: return 1.0;
    case WeightRule::kMajorAxisLambda: {
      Eigen::Vector3d n;
      double lambda = 0.0;
      major_axis(P, &n, &lambda);
      return lambda;
    }
    case WeightRule::kAllAxesLambda: return P.trace();
  }
  return 1.0;
}

}  // namespace

PlaneQuadratic plane_quadratic(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Matrix3d>& covariances,
                               WeightRule rule) {
  assert(points.size() == covariances.size());
  PlaneQuadratic f;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& y = points[i];
    if (rule == WeightRule::kAllAxesLambda) {
      // Eq. (3.23)-(3.24): sum_j lambda_j n_j n_j^T = P and sum_j lambda_j (n_j . y) n_j = P y.
      const Eigen::Vector3d Py = covariances[i] * y;
      f.A += covariances[i];
      f.b += Py;
      f.c += y.dot(Py);
      continue;
    }
    Eigen::Vector3d n;
    double lambda = 0.0;
    major_axis(covariances[i], &n, &lambda);
    const double w = rule == WeightRule::kMajorAxisUnit ? 1.0 : lambda;  // eq. (3.21) / (3.22)
    const double d = n.dot(y);                                            // eq. (3.8): the plane through y_i
    f.A += w * n * n.transpose();                                         // eq. (3.10)
    f.b += w * d * n;
    f.c += w * d * d;                                                     // eq. (3.11)
  }
  return f;
}

SphereMinimum minimize_on_sphere(const PlaneQuadratic& f, const Eigen::Vector3d& m, double r,
                                 const Eigen::Vector3d& preferred_direction) {
  assert(r > 0.0);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(f.A);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // ascending, as the seed sorts them
  const Eigen::Matrix3d phi = eig.eigenvectors();
  // Eq. (3.14)-(3.15): in coordinates centred on m, A y - b' = mu y with b' = b - A m.
  const Eigen::Vector3d b_prime = f.b - f.A * m;
  const Eigen::Vector3d beta = phi.transpose() * b_prime;  // eq. (3.17)
  const double scale = b_prime.norm() + lambda.cwiseAbs().maxCoeff() * r + 1e-300;
  // E_1 of eq. (3.20): the eigenvalues equal to lambda_1 (to rounding).
  const double eig_tol = 1e-10 * std::max(lambda.cwiseAbs().maxCoeff(), 1e-300);
  bool in_e1[3];
  double beta_e1_sq = 0.0;
  int e1_count = 0;
  for (int i = 0; i < 3; ++i) {
    in_e1[i] = lambda(i) - lambda(0) <= eig_tol;
    if (in_e1[i]) {
      beta_e1_sq += beta(i) * beta(i);
      ++e1_count;
    }
  }
  const bool degenerate = std::sqrt(beta_e1_sq) <= 1e-12 * scale;

  SphereMinimum out;
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  // The solution part outside E_1 at multiplier mu (the secular function's terms, eq. 3.18).
  auto y_at = [&](double mu, bool skip_e1) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (skip_e1 && in_e1[i]) continue;
      v += beta(i) / (lambda(i) - mu) * phi.col(i);
    }
    return v;
  };
  auto bisect = [&](double lo, double hi, bool skip_e1) {
    // |y(mu)| grows monotonically on (-inf, lambda_1): |y(lo)| <= r <= |y(hi)|.
    for (out.iterations = 0; out.iterations < 200 && hi - lo > 1e-15 * (std::abs(lo) + std::abs(hi) + scale / r); ++out.iterations) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (y_at(mid, skip_e1).squaredNorm() < r * r ? lo : hi) = mid;
    }
    out.mu = 0.5 * (lo + hi);
    return y_at(out.mu, skip_e1);
  };

  if (!degenerate) {
    // Eq. (3.19): the sum is at most |b'|^2 / (lambda_1 - mu)^2, so mu >= lambda_1 - |b'| / r.
    // Eq. (3.20): it is at least sum_{E_1} beta_i^2 / (lambda_1 - mu)^2, so mu <= lambda_1 - sqrt(.) / r.
    const double lo = lambda(0) - b_prime.norm() / r;
    const double hi = lambda(0) - std::sqrt(beta_e1_sq) / r;
    y = bisect(lo, hi, /*skip_e1=*/false);
    out.kind = SphereCase::kBisection;
  } else {
    // Degenerate: b' has (almost) no component along E_1, so the upper bound is lambda_1 itself.
    // If the rest of the solution at mu -> lambda_1 is still shorter than r, the "hard case":
    // mu = lambda_1 and the missing length goes along E_1 (either sign, equally good).
    const Eigen::Vector3d y_rest = y_at(lambda(0), /*skip_e1=*/true);
    if (e1_count < 3 && y_rest.norm() >= r) {
      y = bisect(lambda(0) - b_prime.norm() / r, lambda(0), /*skip_e1=*/true);
      out.kind = SphereCase::kBisection;
    } else {
      out.mu = lambda(0);
      out.kind = (e1_count == 3 && b_prime.norm() <= 1e-12 * scale) ? SphereCase::kAnyPoint : SphereCase::kHardCase;
      Eigen::Vector3d along = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) {
        if (in_e1[i]) along += phi.col(i).dot(preferred_direction) * phi.col(i);
      }
      if (along.norm() < 1e-9) {
        for (int i = 0; i < 3 && along.norm() < 1e-9; ++i) {
          if (in_e1[i]) along = phi.col(i);
        }
      }
      const double tau = std::sqrt(std::max(0.0, r * r - y_rest.squaredNorm()));
      y = y_rest + tau * along.normalized();
    }
  }
  // On the sphere to rounding.
  if (y.norm() > 0.0) y *= r / y.norm();
  out.x_world = m + y;
  out.value = f(out.x_world);
  return out;
}

Eigen::Vector3d weighted_centre(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Matrix3d>& covariances,
                                WeightRule rule) {
  assert(points.size() == covariances.size());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double w = point_weight(covariances[i], rule);
    sum += w * points[i];
    total += w;
  }
  if (total > 0.0) return sum / total;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  return points.empty() ? mean : Eigen::Vector3d(mean / static_cast<double>(points.size()));
}

CovarianceView plan_covariance_view(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Matrix3d>& covariances,
                                    WeightRule rule, const Eigen::Vector3d& sphere_center, double sphere_radius,
                                    const Eigen::Vector3d& up_world) {
  CovarianceView view;
  view.minimum = minimize_on_sphere(plane_quadratic(points, covariances, rule), sphere_center, sphere_radius, up_world);
  view.look_at_world = weighted_centre(points, covariances, rule);
  view.T_world_camera = look_at(view.minimum.x_world, view.look_at_world, up_world);
  return view;
}

Eigen::Matrix3d depth_point_covariance(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& centers,
                                       const SensorModel& sensor, double focal_px, double prior_sigma_m) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity() / (prior_sigma_m * prior_sigma_m);
  for (const auto& c : centers) {
    const Eigen::Vector3d ray = p - c;
    const double range = ray.norm();
    if (range <= 0.0) continue;
    const Eigen::Vector3d u = ray / range;
    const double sigma_axial = sensor.sigma_z(range);
    const double sigma_lateral = range * sensor.lateral_px / focal_px;
    const Eigen::Matrix3d along = u * u.transpose();
    information += along / (sigma_axial * sigma_axial) + (Eigen::Matrix3d::Identity() - along) / (sigma_lateral * sigma_lateral);
  }
  return information.inverse();
}

}  // namespace scenewatch::planning
