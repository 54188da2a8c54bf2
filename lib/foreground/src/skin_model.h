#pragma once
/// The skin model: which colours are skin, per pixel, in YCrCb with a luminance and a saturation
/// gate. Private to the foreground module.
#include <cstdint>
#include <vector>

namespace scenewatch::foreground {

/// True when an sRGB colour is skin.
bool is_skin(std::uint8_t r, std::uint8_t g, std::uint8_t b);

/// The skin mask of an interleaved RGB image (w * h * 3 bytes): 1 where skin, 0 elsewhere.
/// Converts through OpenCV's YCrCb (the same transform `is_skin` applies to one pixel).
std::vector<std::uint8_t> skin_mask(const std::vector<std::uint8_t>& rgb, int width, int height);

}  // namespace scenewatch::foreground
