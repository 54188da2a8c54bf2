#pragma once
/// The seed's reconstruction experiment (D5.1 section 3.1.2.4 and 3.1.2.6): static points
/// reconstructed by an EKF from the pixel measurements of two cameras, one fixed and one that
/// jumps, at every step, to the position the planner chooses (or to a random one).
///
/// Simplification, stated: the seed's EKF also estimates both cameras' states (eq. 3.1-3.4); here
/// the camera poses are known, so the points' covariance blocks stay independent and each point is
/// its own 3-state EKF with the pinhole measurement of eq. (3.5)-(3.6). What the planner reads,
/// the blocks P_{y_i y_i}, is the same.
#include <cstdint>
#include <optional>
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/planning/covariance_planner.h"

namespace scenewatch::planning {

/// The pixel (u, v) of a world point in a camera with focal length f and the principal point at
/// 0, or nothing behind the camera (eq. 3.5-3.6; the seed's signs flip the image, which changes no
/// covariance).
std::optional<Eigen::Vector2d> project(const Pose& T_world_camera, const Eigen::Vector3d& p_world, double focal_px);

/// Independent 3-state EKFs of static points. NOT thread safe.
class PointFilter {
 public:
  /// Estimates start at `initial_world` with covariance prior_sigma_m^2 I.
  PointFilter(std::vector<Eigen::Vector3d> initial_world, double prior_sigma_m);
  /// One EKF update per point measured by the camera; `pixels[i]` empty: point i not seen.
  void update(const Pose& T_world_camera, const std::vector<std::optional<Eigen::Vector2d>>& pixels, double focal_px,
              double sigma_px);
  const std::vector<Eigen::Vector3d>& estimates() const { return estimates_; }
  const std::vector<Eigen::Matrix3d>& covariances() const { return covariances_; }
  /// The trace of the points' covariance (the sum of the blocks' traces): Fig. 3.12's measure.
  double trace() const;
  /// The spectral norm of the points' covariance (block diagonal: the largest block eigenvalue).
  double spectral_norm() const;

 private:
  std::vector<Eigen::Vector3d> estimates_;
  std::vector<Eigen::Matrix3d> covariances_;
};

/// The fixed set-up of the reproduction (the seed gives none of these numbers; chosen here and
/// kept fixed across every comparison).
struct TwoCameraExperiment {
  int points = 100;                 ///< uniform in a cube
  double cube_side_m = 0.3;         ///< centred on the origin
  double sphere_radius_m = 1.0;     ///< both cameras on this sphere around the origin
  double focal_px = 500.0;
  double sigma_px = 1.0;            ///< pixel noise, 1 sigma
  double prior_sigma_m = 0.1;       ///< the points' initial uncertainty
  int steps = 200;
  Eigen::Vector3d fixed_camera_world = Eigen::Vector3d(0.0, -1.0, 0.0);  ///< scaled onto the sphere
};

/// Where the moving camera goes.
struct ViewStrategy {
  bool random = false;                         ///< uniform on the sphere
  WeightRule rule = WeightRule::kAllAxesLambda;  ///< otherwise the seed's planner with this rule
};

/// Per step (0-based, after the step's update): the trace and spectral norm of the points'
/// covariance.
struct ExperimentCurve {
  std::vector<double> trace, spectral_norm;
};

/// One run; `seed` draws the points, their initial estimates, the noise and the random views.
/// The points (and so the scene) depend on `scene_seed` only, so strategies compare on one scene.
ExperimentCurve run_two_camera_experiment(const TwoCameraExperiment& setup, const ViewStrategy& strategy,
                                          std::uint64_t scene_seed, std::uint64_t run_seed);

}  // namespace scenewatch::planning
