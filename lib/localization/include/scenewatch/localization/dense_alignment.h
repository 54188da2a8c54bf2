#pragma once
/// Dense RGB-D alignment of a frame to a reference view, coarse to fine: projective data
/// association, a point-to-plane term (KinectFusion, Newcombe et al. ISMAR 2011) plus a
/// photometric term (DVO, Kerl et al. ICRA 2013), one Gauss-Newton system per iteration (as
/// Whelan et al.'s ElasticFusion combines them). Geometric residuals are weighed by the sensor
/// model's noise at their depth, photometric ones by their own robust spread; both Huber.
#include <Eigen/Core>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/localization/rgbd_pyramid.h"

namespace scenewatch::localization {

struct AlignmentConfig {
  /// Gauss-Newton iterations per level, coarsest level first; the last entry is level 0.
  std::vector<int> iterations = {10, 6, 4};
  /// Correspondences farther apart than this at the coarsest level are not one surface; the gate
  /// halves with each finer level, and never falls below four noise sigmas at the point's depth.
  double max_correspondence_m = 0.12;
  /// Weight of the photometric term against the geometric one, both normalised by their noise;
  /// 0: geometry only.
  double photometric_weight = 0.1;
  /// Whether the finest level has the photometric term too. Without it the finest level is
  /// aligned on geometry alone, 23 % faster (docs/localization.md); the coarser levels, where the
  /// photometric term widens the basin of convergence, keep it.
  bool photometric_on_finest_level = true;
  /// Per level, coarsest first as `iterations` (the last entry is level 0): the Gauss-Newton
  /// passes take every n-th pixel of a row, shifted by one from row to row (a checkerboard at 2);
  /// levels the list does not reach take every pixel. The quality at the final pose (inliers,
  /// residual, covariance) counts every pixel. At 2 a level's passes cost half, and the poses stay
  /// within 0.1 mm of every pixel's (docs/localization.md). The coarsest level (80x60 for a VGA
  /// frame) keeps every pixel: it sets the basin of convergence.
  std::vector<int> strides = {1, 2, 2};
  /// The stride of level `level` (0: the finest).
  int stride_at(int level) const {
    const int k = static_cast<int>(strides.size()) - 1 - level;
    return k >= 0 ? strides[static_cast<std::size_t>(k)] : 1;
  }
  /// Pixels whose reference intensity gradient is smaller than this (per pixel, 0..1 units) carry
  /// no photometric information and are skipped.
  double min_gradient = 0.01;
  /// Stops a level when an update moves the camera less than this, metres and degrees.
  double converged_m = 1e-4;
  double converged_deg = 0.01;
};

Status validate(const AlignmentConfig& config);

struct Alignment {
  Pose T_reference_current = Pose::Identity();
  /// Current pixels of level 0 with a depth whose point found a reference surface within three
  /// noise sigmas, against all current pixels of level 0 with a depth.
  double inlier_fraction = 0.0;
  std::size_t inliers = 0, valid_pixels = 0;
  /// RMS point-to-plane distance of the inliers at level 0, metres.
  double residual_m = 0.0;
  double mean_depth_m = 0.0;  ///< of the reference surfaces the current points met
  /// Covariance of the pose's error as a twist (translation, rotation; metres, radians) of the
  /// current camera in the reference camera's frame: the inverse of the geometric information.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
  /// The smallest eigenvalue of the normalised information: near 0, the scene does not constrain
  /// some motion (a plane alone, a corridor).
  double conditioning = 0.0;
  int iterations = 0;
};

/// Aligns `current` to `reference` starting at `T_reference_current` (the prior). Both pyramids
/// need the same number of levels; `reference` needs normals and gradients.
Alignment align(const RgbdPyramid& reference, const RgbdPyramid& current, const Pose& prior_T_reference_current,
                const SensorModel& sensor, const AlignmentConfig& config = {});

/// The exponential of a twist (translation, rotation), as a rigid motion.
Pose twist_exp(const Eigen::Matrix<double, 6, 1>& xi);
/// The cross-product matrix of v: skew(v) x = v x x.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
/// The adjoint of T for twists (translation, rotation) applied on the left: exp(Ad_T xi) T =
/// T exp(xi). Moves a twist's covariance from T's frame into the frame T maps to.
Eigen::Matrix<double, 6, 6> twist_adjoint(const Pose& T);

}  // namespace scenewatch::localization
