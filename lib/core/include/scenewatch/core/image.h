#pragma once
/// Plain images owned by value: row-major, no padding.
#include <cstdint>
#include <vector>

namespace scenewatch {

/// 8-bit RGB image.
struct ColorImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 * width * height bytes, R G B
  bool empty() const { return width == 0 || height == 0; }
};

/// 16-bit depth image in millimetres; 0 (and 65535 in 7-Scenes) mean "no depth".
struct DepthImage {
  int width = 0, height = 0;
  std::vector<std::uint16_t> depth_mm;
  bool empty() const { return width == 0 || height == 0; }
  static constexpr std::uint16_t kInvalid = 0;
};

/// 16-bit label image (instance id per pixel, 0 = none).
struct LabelImage {
  int width = 0, height = 0;
  std::vector<std::uint16_t> labels;
};

}  // namespace scenewatch
