#include "scenewatch/io/bag/image_conversion.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "scenewatch/io/rgbd.h"

namespace scenewatch::io::bag {
namespace {

int channels_of(const std::string& e) {
  if (e == "rgb8" || e == "bgr8") return 3;
  if (e == "rgba8" || e == "bgra8") return 4;
  if (e == "mono8" || e == "8UC1") return 1;
  return 0;
}

// Width, height, step and payload agree; `bytes_per_pixel` per pixel.
Status check_layout(const ImageMessage& m, std::size_t bytes_per_pixel) {
  if (m.width == 0 || m.height == 0 || m.width > 100000 || m.height > 100000) {
    return invalid_argument("image of " + std::to_string(m.width) + "x" + std::to_string(m.height) + " pixels");
  }
  const std::uint64_t row = std::uint64_t{m.width} * bytes_per_pixel;
  if (m.step < row) {
    return invalid_argument("step " + std::to_string(m.step) + " is less than a row of " + std::to_string(m.width) + " '" +
                            m.encoding + "' pixels (" + std::to_string(row) + " bytes)");
  }
  if (std::uint64_t{m.step} * m.height > m.size) {
    return invalid_argument("data has " + std::to_string(m.size) + " bytes, step " + std::to_string(m.step) + " x height " +
                            std::to_string(m.height) + " needs " + std::to_string(std::uint64_t{m.step} * m.height));
  }
  return {};
}

Error unknown_encoding(const std::string& e, const char* known) {
  return invalid_argument("unknown image encoding '" + e + "' (known: " + known + ")");
}

}  // namespace

bool is_color_encoding(const std::string& e) { return channels_of(e) > 0; }
bool is_depth_encoding(const std::string& e) { return e == "16UC1" || e == "mono16" || e == "32FC1"; }

Result<ColorImage> to_color(const ImageMessage& m) {
  const int c = channels_of(m.encoding);
  if (c == 0) return unknown_encoding(m.encoding, "rgb8, bgr8, rgba8, bgra8, mono8");
  if (auto st = check_layout(m, static_cast<std::size_t>(c)); !st) return st.error();
  ColorImage out;
  out.width = static_cast<int>(m.width);
  out.height = static_cast<int>(m.height);
  out.rgb.resize(std::size_t{m.width} * m.height * 3);
  const bool bgr = m.encoding[0] == 'b';
  for (std::uint32_t v = 0; v < m.height; ++v) {
    const std::uint8_t* row = m.data + std::size_t{v} * m.step;
    std::uint8_t* dst = out.rgb.data() + std::size_t{v} * m.width * 3;
    for (std::uint32_t u = 0; u < m.width; ++u, dst += 3) {
      const std::uint8_t* p = row + std::size_t{u} * static_cast<std::size_t>(c);
      if (c == 1) {
        dst[0] = dst[1] = dst[2] = p[0];
      } else {
        dst[0] = bgr ? p[2] : p[0];
        dst[1] = p[1];
        dst[2] = bgr ? p[0] : p[2];
      }
    }
  }
  return out;
}

Result<DepthImage> to_depth(const ImageMessage& m) {
  const bool f32 = m.encoding == "32FC1";
  if (!is_depth_encoding(m.encoding)) return unknown_encoding(m.encoding, "16UC1 or mono16 in millimetres, 32FC1 in metres");
  if (auto st = check_layout(m, f32 ? 4 : 2); !st) return st.error();
  DepthImage out;
  out.width = static_cast<int>(m.width);
  out.height = static_cast<int>(m.height);
  out.depth_mm.resize(std::size_t{m.width} * m.height);
  for (std::uint32_t v = 0; v < m.height; ++v) {
    const std::uint8_t* row = m.data + std::size_t{v} * m.step;
    std::uint16_t* dst = out.depth_mm.data() + std::size_t{v} * m.width;
    for (std::uint32_t u = 0; u < m.width; ++u) {
      std::uint8_t b[4];
      std::memcpy(b, row + std::size_t{u} * (f32 ? 4 : 2), f32 ? 4 : 2);
      if (m.big_endian) std::reverse(b, b + (f32 ? 4 : 2));
      if (!f32) {
        dst[u] = static_cast<std::uint16_t>(b[0] | (b[1] << 8));
        continue;
      }
      float metres;
      std::memcpy(&metres, b, 4);
      const double mm = std::round(double{metres} * 1000.0);
      dst[u] = std::isfinite(mm) && mm > 0 && mm < 65535 ? static_cast<std::uint16_t>(mm) : DepthImage::kInvalid;
    }
  }
  return out;
}

Result<CloudPtr> to_cloud(const PointCloud2Message& m) {
  if (m.height <= 1) return invalid_argument("the PointCloud2 is not organized (height " + std::to_string(m.height) + ")");
  if (m.width == 0 || m.width > 100000 || m.height > 100000) return invalid_argument("PointCloud2 of " + std::to_string(m.width) + "x" + std::to_string(m.height) + " points");
  const PointField* xyz[3] = {nullptr, nullptr, nullptr};
  const PointField* rgb = nullptr;
  for (const auto& f : m.fields) {
    if (f.name.size() == 1 && f.name[0] >= 'x' && f.name[0] <= 'z') xyz[f.name[0] - 'x'] = &f;
    if (f.name == "rgb" || f.name == "rgba") rgb = &f;
  }
  for (int k = 0; k < 3; ++k) {
    if (xyz[k] == nullptr) return invalid_argument(std::string("the PointCloud2 has no field '") + char('x' + k) + "'");
    if (xyz[k]->datatype != 7) return invalid_argument(std::string("PointCloud2 field '") + char('x' + k) + "' is not FLOAT32 (datatype " + std::to_string(xyz[k]->datatype) + ")");
    if (std::uint64_t{xyz[k]->offset} + 4 > m.point_step) return invalid_argument("PointCloud2 field offsets outside point_step");
  }
  if (rgb && std::uint64_t{rgb->offset} + 4 > m.point_step) return invalid_argument("PointCloud2 field 'rgb' outside point_step");
  if (std::uint64_t{m.point_step} * m.width > m.row_step || std::uint64_t{m.row_step} * m.height > m.size) {
    return invalid_argument("PointCloud2 data of " + std::to_string(m.size) + " bytes does not hold " + std::to_string(m.height) +
                            " rows of " + std::to_string(m.row_step) + " bytes with " + std::to_string(m.width) + " points of " +
                            std::to_string(m.point_step));
  }
  auto cloud = std::make_shared<Cloud>();
  cloud->width = m.width;
  cloud->height = m.height;
  cloud->is_dense = false;
  cloud->points.resize(std::size_t{m.width} * m.height);
  auto get = [&](const std::uint8_t* p, std::uint32_t offset) {
    std::uint8_t b[4];
    std::memcpy(b, p + offset, 4);
    if (m.big_endian) std::reverse(b, b + 4);
    float f;
    std::memcpy(&f, b, 4);
    return f;
  };
  for (std::uint32_t v = 0; v < m.height; ++v) {
    for (std::uint32_t u = 0; u < m.width; ++u) {
      const std::uint8_t* p = m.data + std::size_t{v} * m.row_step + std::size_t{u} * m.point_step;
      auto& q = cloud->points[std::size_t{v} * m.width + u];
      q.x = get(p, xyz[0]->offset);
      q.y = get(p, xyz[1]->offset);
      q.z = get(p, xyz[2]->offset);
      if (rgb) {
        const float packed = get(p, rgb->offset);
        std::uint32_t bits;
        std::memcpy(&bits, &packed, 4);
        q.r = static_cast<std::uint8_t>(bits >> 16);
        q.g = static_cast<std::uint8_t>(bits >> 8);
        q.b = static_cast<std::uint8_t>(bits);
      } else {
        q.r = q.g = q.b = 128;
      }
      if (!std::isfinite(q.z) || q.z <= 0) q.x = q.y = q.z = std::numeric_limits<float>::quiet_NaN();
    }
  }
  return cloud;
}

Result<CloudFrame> to_cloud_frame(const PointCloud2Message& m, const std::optional<Intrinsics>& info) {
  auto cloud = to_cloud(m);
  if (!cloud) return cloud.error();
  CloudFrame out;
  out.cloud = *cloud;
  out.has_color = std::any_of(m.fields.begin(), m.fields.end(), [](const PointField& f) { return f.name == "rgb" || f.name == "rgba"; });
  out.intrinsics = info;
  if (!out.intrinsics) {
    if (auto K = estimate_intrinsics(*out.cloud)) out.intrinsics = *K;
  }
  return out;
}

Result<Intrinsics> to_intrinsics(const CameraInfoMessage& m) {
  Intrinsics K;
  K.fx = m.K[0];
  K.fy = m.K[4];
  K.cx = m.K[2];
  K.cy = m.K[5];
  K.width = static_cast<int>(m.width);
  K.height = static_cast<int>(m.height);
  if (!(K.fx > 0 && K.fy > 0 && std::isfinite(K.fx) && std::isfinite(K.fy) && std::isfinite(K.cx) && std::isfinite(K.cy))) {
    return invalid_argument("K has no positive, finite focal lengths (fx " + std::to_string(K.fx) + ", fy " + std::to_string(K.fy) + ")");
  }
  return K;
}

Result<RgbdImages> to_rgbd_images(const ImageMessage& depth_message, const ImageMessage* color_message, Intrinsics K,
                                  const std::string& info_name, bool* color_at_fault) {
  *color_at_fault = false;
  auto depth = to_depth(depth_message);
  if (!depth) return depth.error();
  RgbdImages out;
  ColorImage& color = out.color;
  if (color_message) {
    auto decoded = to_color(*color_message);
    if (decoded && (decoded->width != depth->width || decoded->height != depth->height)) {
      decoded = invalid_argument("the colour image is " + std::to_string(decoded->width) + "x" + std::to_string(decoded->height) +
                                 ", the depth image " + std::to_string(depth->width) + "x" + std::to_string(depth->height) +
                                 " (use a depth topic registered to colour)");
    }
    if (!decoded) {
      *color_at_fault = true;
      return decoded.error();
    }
    color = std::move(*decoded);
  } else {
    color.width = depth->width;
    color.height = depth->height;
    color.rgb.assign(std::size_t(color.width) * color.height * 3, 128);
    out.has_color = false;
  }
  if ((K.width != 0 && K.width != depth->width) || (K.height != 0 && K.height != depth->height)) {
    return invalid_argument("the depth image is " + std::to_string(depth->width) + "x" + std::to_string(depth->height) +
                            ", the camera info on " + info_name + " is for " + std::to_string(K.width) + "x" + std::to_string(K.height));
  }
  K.width = depth->width;
  K.height = depth->height;
  out.depth = std::move(*depth);
  out.intrinsics = K;
  return out;
}

Result<RgbdCloud> to_rgbd_cloud(const ImageMessage& depth_message, const ImageMessage* color_message, Intrinsics K,
                                const std::string& info_name, bool* color_at_fault) {
  auto images = to_rgbd_images(depth_message, color_message, K, info_name, color_at_fault);
  if (!images) return images.error();
  auto cloud = rgbd_to_cloud(images->color, images->depth, images->intrinsics, kDepthMillimetres);
  if (!cloud) return cloud.error();
  return RgbdCloud{*cloud, images->intrinsics, images->has_color};
}

}  // namespace scenewatch::io::bag
