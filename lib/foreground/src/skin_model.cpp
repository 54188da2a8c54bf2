// Skin colour. The chrominance box is Chai & Ngan's (IEEE TCSVT 9(4), 1999, "Face segmentation
// using skin-color map in videophone applications"): 133 <= Cr <= 173 and 77 <= Cb <= 127, which
// holds for light and dark skin alike because it ignores luminance. Three gates are ours, set on the
// hrt1 recordings and the simulator's skin:
//  - luminance Y >= 20: below it JPEG chroma is noise (the black shirt, deep shadow);
//  - saturation (max - min) / max >= 0.32 and R the largest channel (Kovac, Peer & Solina 2003,
//    "Human skin colour clustering for face detection", R > G and R > B): a white table under warm
//    light falls inside the Cr/Cb box but is unsaturated (hrt1's table measures 0.16-0.31, the
//    real forearm 0.6-1.0, the simulator's light skin 0.35-0.40);
//  - hue above ~6 degrees (G - B at least a tenth of R - B): skin hue lies in about 0-50 degrees
//    (Sobottka & Pitas 1998), but its red end is where shaded red objects are.
#include "skin_model.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace scenewatch::foreground {
namespace {

constexpr int kMinY = 20;
constexpr int kCrLow = 133, kCrHigh = 173, kCbLow = 77, kCbHigh = 127;
constexpr double kMinSaturation = 0.32;
constexpr double kMinHueRatio = 0.1;  // (G - B) / (R - B) = hue / 60 degrees

bool skin_ycrcb(int y, int cr, int cb, int r, int g, int b) {
  if (y < kMinY || cr < kCrLow || cr > kCrHigh || cb < kCbLow || cb > kCbHigh) return false;
  if (r <= g || r <= b) return false;
  const int lo = std::min(g, b);
  if ((r - lo) < kMinSaturation * r) return false;
  // Hue at least ~6 degrees towards yellow: shaded saturated red (a red mug's stripes in shadow)
  // passes the Cr/Cb box too, but has G barely above B.
  return g > b && (g - b) >= kMinHueRatio * (r - b);
}

}  // namespace

std::vector<std::uint8_t> skin_mask(const std::vector<std::uint8_t>& rgb, int width, int height) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height, 0);
  if (width <= 0 || height <= 0) return mask;
  const cv::Mat image(height, width, CV_8UC3, const_cast<std::uint8_t*>(rgb.data()));
  cv::Mat ycrcb;
  cv::cvtColor(image, ycrcb, cv::COLOR_RGB2YCrCb);
  for (int v = 0; v < height; ++v) {
    const std::uint8_t* row = ycrcb.ptr<std::uint8_t>(v);
    const std::uint8_t* src = rgb.data() + static_cast<std::size_t>(v) * width * 3;
    for (int u = 0; u < width; ++u) {
      mask[static_cast<std::size_t>(v) * width + u] =
          skin_ycrcb(row[3 * u], row[3 * u + 1], row[3 * u + 2], src[3 * u], src[3 * u + 1], src[3 * u + 2]) ? 1 : 0;
    }
  }
  return mask;
}

std::vector<std::uint8_t> skin_mask(const Cloud& cloud, const std::vector<int>& indices) {
  std::vector<std::uint8_t> rgb;
  rgb.reserve(indices.size() * 3);
  for (int i : indices) {
    const PointT& p = cloud.points[static_cast<std::size_t>(i)];
    rgb.insert(rgb.end(), {p.r, p.g, p.b});
  }
  return skin_mask(rgb, static_cast<int>(indices.size()), 1);
}

bool mostly_skin(const Cloud& cloud, const std::vector<int>& indices) {
  if (indices.empty()) return false;
  const auto skin = skin_mask(cloud, indices);
  std::size_t n = 0;
  for (auto v : skin) n += v ? 1 : 0;
  return 2 * n > indices.size();
}

}  // namespace scenewatch::foreground
