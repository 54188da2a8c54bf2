#include "scenewatch/planning/point_filter.h"

#include <Eigen/Eigenvalues>
#include <cassert>
#include <random>

#include "scenewatch/planning/candidates.h"

namespace scenewatch::planning {

std::optional<Eigen::Vector2d> project(const Pose& T_world_camera, const Eigen::Vector3d& p_world, double f) {
  const Eigen::Vector3d p = T_world_camera.inverse() * p_world;  // eq. (3.5)
  if (p.z() <= 1e-6) return std::nullopt;
  return Eigen::Vector2d(f * p.x() / p.z(), f * p.y() / p.z());  // eq. (3.6), principal point at 0
}

PointFilter::PointFilter(std::vector<Eigen::Vector3d> initial_world, double prior_sigma_m)
    : estimates_(std::move(initial_world)),
      covariances_(estimates_.size(), Eigen::Matrix3d::Identity() * prior_sigma_m * prior_sigma_m) {}

void PointFilter::update(const Pose& T_world_camera, const std::vector<std::optional<Eigen::Vector2d>>& pixels, double f,
                         double sigma_px) {
  assert(pixels.size() == estimates_.size());
  const Pose T_camera_world = T_world_camera.inverse();
  const Eigen::Matrix3d R_cw = T_camera_world.linear();
  const Eigen::Matrix2d R_noise = Eigen::Matrix2d::Identity() * sigma_px * sigma_px;
  for (std::size_t i = 0; i < estimates_.size(); ++i) {
    if (!pixels[i]) continue;
    const Eigen::Vector3d p = T_camera_world * estimates_[i];
    if (p.z() <= 1e-6) continue;
    Eigen::Matrix<double, 2, 3> dh_dp;
    dh_dp << f / p.z(), 0.0, -f * p.x() / (p.z() * p.z()), 0.0, f / p.z(), -f * p.y() / (p.z() * p.z());
    const Eigen::Matrix<double, 2, 3> H = dh_dp * R_cw;
    Eigen::Matrix3d& P = covariances_[i];
    const Eigen::Matrix2d S = H * P * H.transpose() + R_noise;
    const Eigen::Matrix<double, 3, 2> K = P * H.transpose() * S.inverse();
    const Eigen::Vector2d predicted(f * p.x() / p.z(), f * p.y() / p.z());
    estimates_[i] += K * (*pixels[i] - predicted);
    // Joseph form: stays symmetric and positive definite over hundreds of updates.
    const Eigen::Matrix3d I_KH = Eigen::Matrix3d::Identity() - K * H;
    P = I_KH * P * I_KH.transpose() + K * R_noise * K.transpose();
  }
}

double PointFilter::trace() const {
  double sum = 0.0;
  for (const auto& P : covariances_) sum += P.trace();
  return sum;
}

double PointFilter::spectral_norm() const {
  double largest = 0.0;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  for (const auto& P : covariances_) {
    eig.computeDirect(P, Eigen::EigenvaluesOnly);
    largest = std::max(largest, eig.eigenvalues()(2));
  }
  return largest;
}

ExperimentCurve run_two_camera_experiment(const TwoCameraExperiment& setup, const ViewStrategy& strategy,
                                          std::uint64_t scene_seed, std::uint64_t run_seed) {
  std::mt19937_64 scene_rng(scene_seed), rng(run_seed);
  std::uniform_real_distribution<double> cube(-0.5 * setup.cube_side_m, 0.5 * setup.cube_side_m);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> truth(static_cast<std::size_t>(setup.points)), initial(truth.size());
  for (auto& p : truth) p = Eigen::Vector3d(cube(scene_rng), cube(scene_rng), cube(scene_rng));
  for (std::size_t i = 0; i < truth.size(); ++i) {
    initial[i] = truth[i] + setup.prior_sigma_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
  }
  PointFilter filter(initial, setup.prior_sigma_m);
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  const Pose fixed = look_at(setup.sphere_radius_m * setup.fixed_camera_world.normalized(), centre);
  auto measure = [&](const Pose& T_world_camera) {
    std::vector<std::optional<Eigen::Vector2d>> pixels(truth.size());
    for (std::size_t i = 0; i < truth.size(); ++i) {
      pixels[i] = project(T_world_camera, truth[i], setup.focal_px);
      if (pixels[i]) *pixels[i] += setup.sigma_px * Eigen::Vector2d(unit(rng), unit(rng));
    }
    return pixels;
  };
  ExperimentCurve curve;
  for (int step = 0; step < setup.steps; ++step) {
    Pose moving;
    if (strategy.random) {
      Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
      moving = look_at(centre + setup.sphere_radius_m * d.normalized(), centre);
    } else {
      moving = plan_covariance_view(filter.estimates(), filter.covariances(), strategy.rule, centre, setup.sphere_radius_m)
                   .T_world_camera;
    }
    filter.update(fixed, measure(fixed), setup.focal_px, setup.sigma_px);
    filter.update(moving, measure(moving), setup.focal_px, setup.sigma_px);
    curve.trace.push_back(filter.trace());
    curve.spectral_norm.push_back(filter.spectral_norm());
  }
  return curve;
}

}  // namespace scenewatch::planning
