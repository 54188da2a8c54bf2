#pragma once
/// The expected view at a pose: expected depth from the background mesh, and per pixel up to
/// seven colour samples from the nearest keyframes that see the same surface point unoccluded
/// (the seed's view-dependent image database, D5.1 section 4.2), summarised per opponent channel
/// as the number of samples, their mean and their sum of squared deviations.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "scenewatch/background/appearance.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/surprise/bayes.h"

namespace scenewatch::surprise {

struct ExpectedViewConfig {
  int max_samples = kMaxSamples;  ///< reference keyframes sampled per pixel, at most 7
  /// A keyframe sees a surface point unoccluded when its depth there agrees with the point's
  /// depth in it within tolerance_m + tolerance_rel * depth.
  double depth_tolerance_m = 0.01;
  double depth_tolerance_rel = 0.02;
  /// Holes in the expected depth up to this many pixels wide (per 640 pixels of image width)
  /// are filled when the surfaces on both sides agree within fill_holes_max_jump of the depth.
  int fill_holes_px = 40;
  /// Colour samples are drawn on a grid of this many pixels per 640 pixels of width (2: every
  /// second pixel of a VGA image, every pixel at 320x240); pixels between share their grid
  /// neighbour's samples when they lie on the same surface, else draw their own.
  int sample_step_px = 2;
  double fill_holes_max_jump = 0.05;
};

Status validate(const ExpectedViewConfig& config);

struct ExpectedView {
  int width = 0, height = 0;
  Pose T_world_camera = Pose::Identity();
  Intrinsics intrinsics;
  std::vector<float> depth_m;        ///< expected depth, 0 where the model has no surface
  std::vector<std::uint8_t> count;   ///< colour samples per pixel
  std::array<std::vector<float>, kChannels> mean, ssd;  ///< per opponent channel
  std::size_t reference_views = 0;   ///< keyframes that were sampled
  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
};

/// Renders the expected view of `memory` at a pose: depth from the mesh patches of the nearest
/// keyframes, colour samples from the `max_samples` nearest keyframes.
ExpectedView render_expected_view(const background::AppearanceMemory& memory, const Pose& T_world_camera,
                                  const Intrinsics& intrinsics, const ExpectedViewConfig& config = {});

/// The same from an expected depth and explicit reference keyframes (at most kMaxSamples used).
ExpectedView sample_expected_view(const background::DepthMap& depth,
                                  const std::vector<std::shared_ptr<const background::Keyframe>>& references,
                                  const Pose& T_world_camera, const Intrinsics& intrinsics,
                                  const ExpectedViewConfig& config = {});

/// A surface the mesh may lack, in the world frame: a described object's completed primitive
/// (issue 13: its whole surface, the side never seen included), which predicts that object when it
/// is seen from a new side.
struct KnownSurface {
  std::vector<Eigen::Vector3d> points_world;
  double spacing_m = 0.004;                       ///< between neighbouring points
  Eigen::Vector3f rgb = Eigen::Vector3f::Zero();  ///< 0..255, the object's mean colour
  /// The covariance of the object's colours (0..255 units squared; zero: one colour).
  Eigen::Matrix3f rgb_covariance = Eigen::Matrix3f::Zero();
};

/// Splats `surface` into `view` as a z-buffer: each point covers the pixels of a square of
/// spacing_m at its depth; where it is nearer than the expected depth by more than tolerance_m, or
/// the mesh has no surface there, it becomes the expected depth, and the object's colours the
/// pixel's samples (the mesh's samples there belong to a surface it now hides): their mean, and
/// their spread as if every reference view had seen it. An unseen side is predicted to look like
/// the seen one: a striped can's white and red both belong to it. Returns the pixels changed.
std::size_t splat_surface(ExpectedView& view, const KnownSurface& surface, double tolerance_m = 0.01);

/// The virtual image: the mean colour per pixel (the seed's Fig. 4.4 right); black where no sample.
ColorImage expected_color(const ExpectedView& view);

}  // namespace scenewatch::surprise
