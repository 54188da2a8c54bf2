#pragma once
// Depth steps in an organized cloud: where the surface seen in one pixel does not continue into
// its neighbour's (a book lying on a book, a box in front of a box). The two pixels' ranges must
// differ by more than their noise allows, and the surfaces on both sides must miss each other:
// a line is fitted to the
// ranges of up to five pixels on each side of the pair, along the pair's direction; both lines
// are carried to the boundary between the two pixels. On one surface, smooth or creased, they
// meet there; across a step they miss each other by its height. They must miss by more than
// `noise_sigmas` standard deviations of that difference, from the sensor's axial noise at that
// range and incidence (Nguyen, Izadi & Lovell 2012): a threshold that scales with range instead
// of one fitted to a scene.
//
// Pixels within the sensor's lateral noise band of a hole (core/depth_validity.h: a projector's
// shadow, a stereo camera's unmatched pixels) may be the rim of a measurement, and a stereo
// camera's holes leave ragged rims that look like steps. There, a pair is a step only when both
// sides are measured over three pixels or more and scatter about their lines within the noise the
// sensor model gives them. A structured-light sensor's projector leaves a shadow beside nearly
// every occluding edge, so without this most steps between objects went unseen (2026-12-03).
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::segmentation {

struct DepthStepParams {
  SensorModel sensor;         ///< structured light (Kinect v1 class) by default
  double noise_sigmas = 3.0;  ///< a miss beyond this many sigmas of its noise is a step
};

/// Step test on one organized cloud, for pixels in one rectangle of its image (a cluster's
/// bounding box); holds a reference to the cloud. Thread safe (no state after construction).
class DepthSteps {
 public:
  /// Pixels (u, v) with u in [u0, u1], v in [v0, v1] can be tested.
  DepthSteps(const Cloud& cloud, const Eigen::Vector3d& sensor_origin, const DepthStepParams& params, int u0, int v0,
             int u1, int v1);
  /// Whether the surface steps between pixel `a` and pixel `a + offset` (offset 1: the right
  /// neighbour, offset width: the one below). Both pixels valid, in the rectangle; when either
  /// lies in the noise band of a hole, both sides must also be clean rims (clean_rim).
  bool is_step(int a, int offset) const;

 private:
  struct Side {
    double at_boundary = 0.0;  ///< the side's line carried to the boundary
    double variance = 1.0;     ///< its variance, in units of the pixel noise's variance
    double slope = 0.0;        ///< range change per pixel away from the boundary
    double scatter = 0.0;      ///< variance of the ranges about the line (0 below three pixels)
    int pixels = 0;
  };
  /// The line through pixel `first` and up to kSidePixels - 1 more at `first + k * away`.
  Side fit(int first, int away) const;
  /// The sensor model's variance of a side's pixels (axial at its range and incidence, plus the
  /// lateral noise carried along its slope), without the side's own scatter.
  double model_variance(const Side& s, int first, int away) const;
  /// A side measured over three pixels or more, scattered about its line within noise_sigmas
  /// of the model's noise (its `model_variance`).
  bool clean_rim(const Side& s, double model_variance) const;
  /// Range of pixel i from the sensor, NaN when invalid or outside the padded rectangle.
  float range(int i) const;
  /// Whether pixel i lies in the padded rectangle, outside a hole's noise band.
  bool off_hole(int i) const;

  const Cloud& cloud_;
  Eigen::Vector3f origin_;
  DepthStepParams params_;
  int u0_, v0_, w_, h_;          ///< the rectangle, padded by the sides' reach
  std::vector<float> ranges_;    ///< over the padded rectangle
  std::vector<std::uint8_t> off_hole_;  ///< over the padded rectangle: outside a hole's noise band
};

}  // namespace scenewatch::segmentation
