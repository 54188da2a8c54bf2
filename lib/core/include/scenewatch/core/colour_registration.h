#pragma once
/// Where a depth pixel's colour really lies in the colour image, when the two cameras are not
/// registered (issue 28's sensor model: "the misregistration between colour and depth").
///
/// A Kinect v1 recorded raw, as 7-Scenes is, has a colour camera with a wider view than its depth
/// camera (focal length about 525 against 585 px) and a baseline between them: a depth pixel's
/// colour is found 10 % nearer the image centre and some pixels aside. Texture, surprise, the
/// photometric term of the tracker and the hand detector then read the colour of a neighbouring
/// surface at every edge.
///
/// The registration is measured from the frames themselves, with no calibration file: an
/// occluding contour in depth is an edge in colour too, so the colour image's gradient, sampled
/// along the depth image's edges, is largest where the two are registered (the principle of
/// Levinson & Thrun's target-free camera-lidar calibration, RSS 2013). The model is a scale about
/// the principal point and a shift; a baseline's parallax, which varies with depth, was fitted
/// too on 7-Scenes and changed the score by 0.1 %, so it is left out.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch {

/// The colour pixel of depth pixel (u, v): (cx + scale (u - cx) + shift_x, cy + scale (v - cy) +
/// shift_y), with (cx, cy) the depth camera's principal point.
struct ColourRegistration {
  double scale = 1.0;
  double shift_x_px = 0.0;
  double shift_y_px = 0.0;

  /// The farthest any pixel of a width x height image moves, pixels.
  double max_displacement_px(int width, int height, double cx, double cy) const;
};

struct ColourRegistrationFit {
  ColourRegistration registration;
  /// Mean colour gradient along the depth edges at the fit and with the images as they are.
  double score = 0.0;
  double identity_score = 0.0;
  std::size_t edge_pixels = 0;
};

/// The registration that best lays the colour edges of an organized RGB-D cloud onto its depth
/// edges (steps beyond depth_edge_step_m, between two measured pixels), searched over scales
/// 0.80-1.25 and shifts up to 20 px across, 10 px down; coarse to fine, to a quarter pixel.
/// Nothing when the cloud is not organized or has fewer depth-edge pixels than it is wide (no
/// occluding contour across the view to measure against).
std::optional<ColourRegistrationFit> fit_colour_registration(const Cloud& organized, const Intrinsics& K,
                                                             const SensorModel& sensor);

/// A registration laid out for one image: each depth pixel's four colour taps and their weights,
/// so that a camera's frames are registered by a gather rather than a search.
class ColourRemap {
 public:
  ColourRemap(int width, int height, const Intrinsics& K, const ColourRegistration& registration);
  /// True when the cloud is organized at this remap's size.
  bool fits(const Cloud& cloud) const { return static_cast<int>(cloud.width) == width_ && static_cast<int>(cloud.height) == height_; }
  /// A copy of the cloud whose colours are read, bilinearly, where the registration says each
  /// pixel's colour lies (clamped to the image). Points keep their coordinates. Needs fits().
  CloudPtr apply(const Cloud& organized) const;
  /// The same, written into `out` in one pass (its storage is reused when it has the size
  /// already: a camera's frames need no fresh 10 MB each). `out` must not be `organized`.
  void apply(const Cloud& organized, Cloud& out) const;

 private:
  int width_ = 0, height_ = 0;
  // The registration scales and shifts each axis on its own, so a pixel's taps are its column's
  // and its row's: 1,120 entries rather than a table per pixel to stream through every frame.
  struct Tap {
    int first = 0;          ///< the left (top) tap's column (row)
    float weight = 0.0f;    ///< the right (lower) tap's weight
  };
  std::vector<Tap> columns_, rows_;
};

/// ColourRemap(...).apply(organized), once.
CloudPtr apply_colour_registration(const Cloud& organized, const Intrinsics& K, const ColourRegistration& registration);

/// A camera's registration: the first fit of one of its frames with contours to fit, kept for
/// every frame after it. One fit and not a running estimate, because the memory must see all of
/// a camera's frames registered alike: keyframes registered half a pixel apart (a median that
/// settled over five frames) made image surprise speak when a view returned. A camera whose
/// first 30 frames had nothing to fit (a tabletop seen from above) is not fitted again.
class ColourRegistrationEstimate {
 public:
  /// Fits this frame while there is no registration yet and fewer than 30 frames were tried.
  std::optional<ColourRegistration> update(const Cloud& organized, const Intrinsics& K, const SensorModel& sensor);
  std::optional<ColourRegistration> current() const { return registration_; }
  bool settled() const { return registration_.has_value() || tried_ >= kMaxTries; }

 private:
  static constexpr std::size_t kMaxTries = 30;
  std::size_t tried_ = 0;
  std::optional<ColourRegistration> registration_;
};

}  // namespace scenewatch
