#pragma once
/// The skin model: which colours are skin, per pixel, in YCrCb with a luminance and a saturation
/// gate. Private to the foreground module.
#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::foreground {

/// The skin mask of an interleaved RGB image (w * h * 3 bytes): 1 where skin, 0 elsewhere.
/// Converts through OpenCV's YCrCb (ITU-R BT.601).
std::vector<std::uint8_t> skin_mask(const std::vector<std::uint8_t>& rgb, int width, int height);

/// The same for the points `indices` of a cloud: 1 per index whose colour is skin, in their order.
std::vector<std::uint8_t> skin_mask(const Cloud& cloud, const std::vector<int>& indices);

/// True when most of the points `indices` of a cloud (more than half) have skin colour.
bool mostly_skin(const Cloud& cloud, const std::vector<int>& indices);

}  // namespace scenewatch::foreground
