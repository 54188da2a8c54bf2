// ORB features with depth, and their file.
#include "scenewatch/localization/keyframe_features.h"

#include <cmath>
#include <algorithm>
#include <cstring>
#include <fstream>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "scenewatch/core/cloud.h"

namespace scenewatch::localization {
namespace {

constexpr char kMagic[8] = {'S', 'W', 'O', 'R', 'B', '0', '0', '1'};

// Depth in metres at a keypoint, or 0: the pixel and its 8 neighbours must all have a depth the
// sensor trusts and lie within four noise sigmas of each other (a keypoint on a depth edge would
// take the point of either side).
float depth_at(const DepthImage& depth, int u, int v, const SensorModel& sensor) {
  if (u < 1 || v < 1 || u + 1 >= depth.width || v + 1 >= depth.height) return 0.0f;
  const std::uint16_t center = depth.depth_mm[static_cast<std::size_t>(v) * depth.width + u];
  const double z = center * 0.001;
  if (center == DepthImage::kInvalid || center == 65535 || !sensor.in_range(z)) return 0.0f;
  const double tolerance_mm = 4000.0 * sensor.sigma_z(z);
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const std::uint16_t d = depth.depth_mm[static_cast<std::size_t>(v + dv) * depth.width + u + du];
      if (d == DepthImage::kInvalid || d == 65535 || std::abs(static_cast<double>(d) - center) > tolerance_mm) return 0.0f;
    }
  return static_cast<float>(z);
}

template <typename T>
void put(std::ofstream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
bool get(std::ifstream& in, T& value) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&value), sizeof(T)));
}

}  // namespace

Status validate(const FeatureConfig& c) {
  if (c.max_features < 50 || c.max_features > 10000) return invalid_argument("localization.max_features: must be in [50, 10000]");
  if (!(c.scale_factor > 1.0 && c.scale_factor <= 2.0)) return invalid_argument("localization.feature_scale_factor: must be in (1, 2]");
  if (c.levels < 1 || c.levels > 12) return invalid_argument("localization.feature_levels: must be in [1, 12]");
  return {};
}

ViewFeatures extract_features(const ColorImage& color, const DepthImage& depth, const Intrinsics& K, const SensorModel& sensor,
                              const FeatureConfig& config) {
  ViewFeatures out;
  if (color.empty() || depth.width != color.width || depth.height != color.height) return out;
  const cv::Mat rgb(color.height, color.width, CV_8UC3, const_cast<std::uint8_t*>(color.rgb.data()));
  cv::Mat gray;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  auto orb = cv::ORB::create(config.max_features, static_cast<float>(config.scale_factor), config.levels);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(gray, cv::noArray(), keypoints, descriptors);
  // Strongest first (ORB ranks keypoints by their Harris response): retrieval uses the first few.
  std::vector<std::size_t> order(keypoints.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keypoints[a].response > keypoints[b].response; });
  for (std::size_t i : order) {
    const cv::Point2f& p = keypoints[i].pt;
    const float z = depth_at(depth, static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)), sensor);
    if (z <= 0.0f) continue;
    out.points_camera.emplace_back(static_cast<float>((p.x - K.cx) / K.fx) * z, static_cast<float>((p.y - K.cy) / K.fy) * z, z);
    out.pixel_size.push_back(static_cast<float>(std::pow(config.scale_factor, keypoints[i].octave)));
    Descriptor d;
    std::memcpy(d.data(), descriptors.ptr<std::uint8_t>(static_cast<int>(i)), d.size());
    out.descriptors.push_back(d);
  }
  return out;
}

ViewFeatures extract_features(const Frame& frame, const SensorModel& sensor, const FeatureConfig& config) {
  if (!frame.cloud || !frame.intrinsics || !frame.intrinsics->valid() || frame.cloud->height <= 1 ||
      frame.cloud->width != static_cast<std::uint32_t>(frame.intrinsics->width) ||
      frame.cloud->height != static_cast<std::uint32_t>(frame.intrinsics->height))
    return {};
  const Cloud& cloud = *frame.cloud;
  ColorImage color{static_cast<int>(cloud.width), static_cast<int>(cloud.height), {}};
  DepthImage depth{color.width, color.height, {}};
  color.rgb.resize(3 * cloud.size());
  depth.depth_mm.assign(cloud.size(), DepthImage::kInvalid);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& p = cloud.points[i];
    color.rgb[3 * i] = p.r, color.rgb[3 * i + 1] = p.g, color.rgb[3 * i + 2] = p.b;
    if (is_valid(p) && p.z > 0 && p.z < 65.0f) depth.depth_mm[i] = static_cast<std::uint16_t>(std::lround(p.z * 1000.0f));
  }
  return extract_features(color, depth, *frame.intrinsics, sensor, config);
}

Status save_features(const std::filesystem::path& path, const std::vector<SavedFeatures>& records) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return io_error("'" + path.string() + "': cannot open for writing");
  out.write(kMagic, sizeof(kMagic));
  put(out, static_cast<std::uint64_t>(records.size()));
  for (const auto& r : records) {
    const Eigen::Matrix4d m = r.T_world_camera.matrix();
    for (int i = 0; i < 16; ++i) put(out, m(i / 4, i % 4));
    put(out, static_cast<std::uint64_t>(r.features.size()));
    for (std::size_t i = 0; i < r.features.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(out, r.features.points_camera[i][k]);
      put(out, r.features.pixel_size[i]);
      out.write(reinterpret_cast<const char*>(r.features.descriptors[i].data()), sizeof(Descriptor));
    }
  }
  out.flush();
  if (!out) return io_error("'" + path.string() + "': write failed");
  return {};
}

Result<std::vector<SavedFeatures>> load_features(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error("'" + path.string() + "': cannot open");
  char magic[sizeof(kMagic)];
  if (!in.read(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
    return invalid_argument("'" + path.string() + "': not a scenewatch keyframe feature file");
  const auto truncated = [&] { return invalid_argument("'" + path.string() + "': truncated keyframe feature file"); };
  std::uint64_t count = 0;
  if (!get(in, count) || count > 100000) return truncated();
  std::vector<SavedFeatures> records(count);
  for (auto& r : records) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i)
      if (!get(in, m(i / 4, i % 4))) return truncated();
    if (auto st = validate_rigid(m); !st) return invalid_argument("'" + path.string() + "': " + st.error().message);
    r.T_world_camera = pose_from_matrix(m);
    std::uint64_t n = 0;
    if (!get(in, n) || n > 100000) return truncated();
    r.features.points_camera.resize(n);
    r.features.pixel_size.resize(n);
    r.features.descriptors.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k)
        if (!get(in, r.features.points_camera[i][k])) return truncated();
      if (!get(in, r.features.pixel_size[i])) return truncated();
      if (!in.read(reinterpret_cast<char*>(r.features.descriptors[i].data()), sizeof(Descriptor))) return truncated();
    }
  }
  return records;
}

}  // namespace scenewatch::localization
