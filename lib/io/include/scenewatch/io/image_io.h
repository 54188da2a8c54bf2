#pragma once
/// PNG images: 8-bit colour, 16-bit depth in millimetres, 16-bit labels.
#include <filesystem>
#include <string>
#include <utility>

#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// Reads an 8-bit RGB (or RGBA, or grey) PNG as RGB.
Result<ColorImage> read_color_png(const std::filesystem::path& path);
/// Reads a 16-bit single-channel PNG of depth in millimetres; an 8-bit file is an error.
Result<DepthImage> read_depth_png(const std::filesystem::path& path);
/// Reads a 16-bit (or 8-bit) single-channel label PNG.
Result<LabelImage> read_label_png(const std::filesystem::path& path);

/// Width and height of a PNG from its IHDR chunk, without decoding the image.
Result<std::pair<int, int>> read_png_size(const std::filesystem::path& path);

/// Writers; each checks the buffer size against width and height.
Status write_color_png(const std::filesystem::path& path, const ColorImage& image);
Status write_depth_png(const std::filesystem::path& path, const DepthImage& image);
Status write_label_png(const std::filesystem::path& path, const LabelImage& image);

/// The PNG file's bytes of a colour image, in memory (for serving it over HTTP).
Result<std::string> encode_color_png(const ColorImage& image);

}  // namespace scenewatch::io
