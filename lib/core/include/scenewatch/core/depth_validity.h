#pragma once
/// Which pixels of a depth image a sensor model lets serve as evidence (issue 28): a pixel with a
/// depth in the working range, at least `border_px` from the image border, and farther than the
/// lateral noise band (SensorModel::edge_band_px) from a depth edge and from a hole. An edge lies between neighbours whose depths differ by more
/// than a surface within 75 degrees of head-on plus the noise of both can explain, or between a
/// depth and a hole (a projector shadow or a reflection beside an object's edge).
#include <cstdint>
#include <vector>

#include "scenewatch/core/sensor_model.h"

namespace scenewatch {

struct DepthValidity {
  /// What a pixel is, as bits; a trusted pixel has all of them.
  enum Bit : std::uint8_t {
    kInRange = 1,   ///< a depth within the sensor's working range
    kInterior = 2,  ///< at least border_px from the image border
    kOffEdge = 4,   ///< outside the lateral noise band of a depth edge
    kOffHole = 8,   ///< outside the lateral noise band of a pixel without depth
  };
  static constexpr std::uint8_t kTrusted = kInRange | kInterior | kOffEdge | kOffHole;
  int width = 0, height = 0;
  std::vector<std::uint8_t> bits;  ///< row-major
  std::size_t valid = 0;           ///< pixels with a depth in range
  std::size_t trusted = 0;         ///< of them, with every bit
  /// True when the pixel lies in the image and has every bit of `required`.
  bool has(int u, int v, std::uint8_t required = kTrusted) const {
    return u >= 0 && v >= 0 && u < width && v < height && (bits[static_cast<std::size_t>(v) * width + u] & required) == required;
  }
};

/// The neighbour-to-neighbour depth step beyond which two pixels at depth z lie on different
/// surfaces, for focal length f: sigma_factor sqrt(2) sigma_z(z) + z tan(75 deg) / f.
double depth_edge_step_m(const SensorModel& sensor, double z_m, double focal_px, double sigma_factor);

/// The validity of a depth image (row-major, metres, NaN or <= 0 where none).
DepthValidity depth_validity(const std::vector<float>& z_m, int width, int height, double focal_px,
                             const SensorModel& sensor, double sigma_factor);

}  // namespace scenewatch
