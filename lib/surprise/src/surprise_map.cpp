#include "scenewatch/surprise/surprise_map.h"

#include "scenewatch/core/files.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace scenewatch::surprise {
namespace {

float percentile(std::vector<float>& values, double q) {
  const std::size_t k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

namespace {

// Each pixel whose surprise reaches `min_kl` is compared again with the expected samples of its
// neighbours within `radius` (nearest first) and keeps the least surprise found: a colour that the
// memory predicts a pixel or two away is misalignment, not change.
void tolerate_misalignment(const ExpectedView& view, const ColorImage& observed, const SurpriseKernel& kernel,
                           int radius, float min_kl, SurpriseMap& map) {
  std::vector<std::pair<int, int>> offsets;
  for (int dv = -radius; dv <= radius; ++dv)
    for (int du = -radius; du <= radius; ++du)
      if (du != 0 || dv != 0) offsets.emplace_back(du, dv);
  std::sort(offsets.begin(), offsets.end(), [](const auto& a, const auto& b) {
    return a.first * a.first + a.second * a.second < b.first * b.first + b.second * b.second;
  });
  const int w = view.width, h = view.height;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (!(map.total[i] >= min_kl)) continue;  // also skips NaN
      // The observed signal again, for the few pixels that get here (no frame-sized copy).
      float obs[kChannels];
      to_opponent(observed.rgb[3 * i], observed.rgb[3 * i + 1], observed.rgb[3 * i + 2], obs);
      for (int c = 0; c < kChannels; ++c) obs[c] = map.photometric.apply(c, obs[c]);
      float best = map.total[i];
      std::array<float, kChannels> best_ch{};
      bool improved = false;
      for (const auto& [du, dv] : offsets) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
        const std::size_t j = static_cast<std::size_t>(vv) * w + uu;
        std::array<float, kChannels> ch{};
        float total = 0;
        for (int c = 0; c < kChannels; ++c) {
          ch[c] = kernel.at(view.count[j], view.mean[c][j], view.ssd[c][j], obs[c]);
          total += ch[c];
        }
        if (!(total < best)) continue;  // NaN (no samples there) never wins
        best = total;
        best_ch = ch;
        improved = true;
        if (best < min_kl) break;
      }
      if (!improved) continue;
      map.total[i] = best;
      for (int c = 0; c < kChannels; ++c) map.channel[c][i] = best_ch[c];
    }
  }
}

}  // namespace

Result<SurpriseMap> compute_surprise(const ExpectedView& view, const ColorImage& observed, const SurpriseKernel& kernel,
                                     const RobustConfig* robust) {
  if (observed.width != view.width || observed.height != view.height)
    return invalid_argument("observed image is " + std::to_string(observed.width) + "x" + std::to_string(observed.height) +
                            " but the expected view is " + std::to_string(view.width) + "x" + std::to_string(view.height));
  const std::size_t n = view.pixel_count();
  if (observed.rgb.size() != 3 * n) return invalid_argument("observed image buffer does not match its size");
  SurpriseMap map;
  map.width = view.width;
  map.height = view.height;
  map.total.resize(n);
  for (auto& channel : map.channel) channel.resize(n);
  if (robust != nullptr && robust->photometric) map.photometric = fit_photometric(view, observed, kernel.min_samples());
  const int radius = robust == nullptr ? 0
                                       : static_cast<int>(std::lround(robust->align_radius_px * view.width / 640.0));
  // The observed opponent signals: in blocks, so that they live in a small buffer rather than in
  // three more frame-sized arrays (fresh pages cost more than the arithmetic here).
  constexpr std::size_t kBlock = 4096;
  std::array<std::array<float, kBlock>, kChannels> obs;
  for (std::size_t start = 0; start < n; start += kBlock) {
    const std::size_t len = std::min(kBlock, n - start);
    for (std::size_t i = 0; i < len; ++i) {
      const std::uint8_t* px = &observed.rgb[3 * (start + i)];
      float opp[kChannels];
      to_opponent(px[0], px[1], px[2], opp);
      for (int c = 0; c < kChannels; ++c) obs[c][i] = map.photometric.apply(c, opp[c]);
    }
    const float* means[kChannels];
    const float* ssds[kChannels];
    const float* observed_ch[kChannels];
    float* outs[kChannels];
    for (int c = 0; c < kChannels; ++c) {
      means[c] = view.mean[c].data() + start;
      ssds[c] = view.ssd[c].data() + start;
      observed_ch[c] = obs[c].data();
      outs[c] = map.channel[c].data() + start;
    }
    kernel.run_channels(kChannels, view.count.data() + start, means, ssds, observed_ch, outs, map.total.data() + start, len);
  }
  if (radius > 0) tolerate_misalignment(view, observed, kernel, radius, static_cast<float>(robust->align_min_kl), map);
  for (std::size_t i = 0; i < n; ++i) map.known_pixels += std::isnan(map.total[i]) ? 0 : 1;
  return map;
}

Status validate(const RegionConfig& c) {
  if (!(c.threshold_low >= 0)) return invalid_argument("surprise.threshold_low must be >= 0");
  if (!(c.threshold_high >= c.threshold_low)) return invalid_argument("surprise.threshold_high must be >= threshold_low");
  if (c.open_radius_px < 0 || c.open_radius_px > 16) return invalid_argument("surprise.open_radius_px must be in [0, 16]");
  if (c.min_area_px < 1) return invalid_argument("surprise.min_area_px must be >= 1");
  if (c.min_extent_px < 0) return invalid_argument("surprise.min_extent_px must be >= 0");
  return {};
}

Status validate(const SurpriseConfig& c) {
  if (auto st = validate(c.view); !st) return st;
  if (auto st = validate(c.robust); !st) return st;
  if (auto st = validate(c.regions); !st) return st;
  if (!(c.prior.a0 > 0)) return invalid_argument("surprise.a0 must be > 0");
  if (!(c.prior.b0 > 0)) return invalid_argument("surprise.b0 must be > 0");
  if (c.familiar_after_frames < 0 || c.familiar_after_frames > 100000)
    return invalid_argument("surprise.familiar_after_frames must be in [0, 100000]");
  if (c.adopt_after_frames < 0 || c.adopt_after_frames > 1000)
    return invalid_argument("surprise.adopt_after_frames must be in [0, 1000]");
  if (c.min_samples < 1 || c.min_samples > kMaxSamples)
    return invalid_argument("surprise.min_samples must be in [1, " + std::to_string(kMaxSamples) + "]");
  return {};
}

std::vector<SurpriseRegion> find_regions(const SurpriseMap& map, const ExpectedView& view, const DepthImage* observed_depth,
                                         const RegionConfig& config) {
  std::vector<SurpriseRegion> regions;
  const int w = map.width, h = map.height;
  if (w == 0 || h == 0) return regions;
  cv::Mat low(h, w, CV_8U), high(h, w, CV_8U);
  for (int i = 0; i < w * h; ++i) {
    const float s = map.total[static_cast<std::size_t>(i)];
    low.data[i] = s >= config.threshold_low ? 255 : 0;  // NaN compares false: unknown is never surprising
    high.data[i] = s >= config.threshold_high ? 255 : 0;
  }
  if (config.open_radius_px > 0) {
    const int k = 2 * config.open_radius_px + 1;
    cv::morphologyEx(low, low, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
  }
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(low, labels, stats, centroids, 8, CV_32S);
  std::vector<char> seeded(static_cast<std::size_t>(count), 0);
  for (int i = 0; i < w * h; ++i) {
    if (high.data[i]) seeded[static_cast<std::size_t>(labels.ptr<int>()[i])] = 1;
  }
  const int min_extent = static_cast<int>(std::lround(config.min_extent_px * w / 640.0));
  std::vector<int> region_of(static_cast<std::size_t>(count), -1);
  for (int l = 1; l < count; ++l) {
    if (!seeded[static_cast<std::size_t>(l)]) continue;
    const int area = stats.at<int>(l, cv::CC_STAT_AREA);
    const int bw = stats.at<int>(l, cv::CC_STAT_WIDTH), bh = stats.at<int>(l, cv::CC_STAT_HEIGHT);
    if (area < config.min_area_px || bw < min_extent || bh < min_extent) continue;
    region_of[static_cast<std::size_t>(l)] = static_cast<int>(regions.size());
    SurpriseRegion r;
    r.region = {stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP), bw, bh,
                static_cast<std::uint32_t>(area)};
    regions.push_back(r);
  }
  for (int i = 0; i < w * h; ++i) {
    const int r = region_of[static_cast<std::size_t>(labels.ptr<int>()[i])];
    if (r >= 0) regions[static_cast<std::size_t>(r)].pixels.push_back(static_cast<std::uint32_t>(i));
  }
  const Intrinsics& K = view.intrinsics;
  for (SurpriseRegion& r : regions) {
    std::array<double, kChannels> sum{};
    double sum_total = 0;
    std::size_t known = 0;
    std::array<std::vector<float>, 3> coords;
    for (std::uint32_t i : r.pixels) {
      if (!std::isnan(map.total[i])) {
        for (int c = 0; c < kChannels; ++c) {
          r.peak[c] = std::max(r.peak[c], static_cast<double>(map.channel[c][i]));
          sum[c] += map.channel[c][i];
        }
        r.peak_total = std::max(r.peak_total, static_cast<double>(map.total[i]));
        sum_total += map.total[i];
        ++known;
      }
      float z = view.depth_m.empty() ? 0.0f : view.depth_m[i];
      if (observed_depth && observed_depth->depth_mm.size() == view.pixel_count()) {
        const std::uint16_t mm = observed_depth->depth_mm[i];
        if (mm != 0 && mm != 65535 && (z <= 0.0f || mm * 0.001f < z)) z = mm * 0.001f;
      }
      if (z <= 0.0f || !K.valid()) continue;
      const int u = static_cast<int>(i % static_cast<std::uint32_t>(w)), v = static_cast<int>(i / static_cast<std::uint32_t>(w));
      const Eigen::Vector3d p = view.T_world_camera * Eigen::Vector3d((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
      for (int k = 0; k < 3; ++k) coords[k].push_back(static_cast<float>(p[k]));
    }
    if (known > 0) {
      for (int c = 0; c < kChannels; ++c) r.mean[c] = sum[c] / static_cast<double>(known);
      r.mean_total = sum_total / static_cast<double>(known);
    }
    r.points_3d = coords[0].size();
    if (r.points_3d > 0) {
      // 2nd to 98th percentile per axis: a few mixed pixels at depth edges do not stretch the box.
      for (int k = 0; k < 3; ++k) {
        r.box_world.min[k] = percentile(coords[k], 0.02);
        r.box_world.max[k] = percentile(coords[k], 0.98);
        r.centroid_world[k] = percentile(coords[k], 0.5);
      }
    }
  }
  std::sort(regions.begin(), regions.end(),
            [](const SurpriseRegion& a, const SurpriseRegion& b) { return a.peak_total > b.peak_total; });
  return regions;
}

Event to_event(const SurpriseRegion& r, double stamp_s) {
  Event e;
  e.stamp_s = stamp_s;
  e.level = EventLevel::kMismatch;
  e.kind = EventKind::kAppearanceChange;
  e.score = r.mean_total;
  e.box_world = r.box_world;
  e.centroid_world = r.centroid_world;
  e.region = r.region;
  for (int c = 0; c < kChannels; ++c) {
    e.evidence[std::string("kl_peak_") + channel_name(c)] = r.peak[c];
    e.evidence[std::string("kl_mean_") + channel_name(c)] = r.mean[c];
  }
  e.evidence["kl_peak_total"] = r.peak_total;
  e.evidence["kl_mean_total"] = r.mean_total;
  e.evidence["area_px"] = r.region.area;
  char buf[160];
  std::snprintf(buf, sizeof buf, "appearance differs over %u px, mean KL %.1f nats (peak %.1f)", r.region.area,
                r.mean_total, r.peak_total);
  e.detail = buf;
  return e;
}

ColorImage heatmap_overlay(const SurpriseMap& map, const ColorImage& observed, double saturation) {
  ColorImage out;
  out.width = map.width;
  out.height = map.height;
  out.rgb.assign(3 * static_cast<std::size_t>(map.width) * map.height, 0);
  cv::Mat scaled(map.height, map.width, CV_8U);
  for (std::size_t i = 0; i < map.total.size(); ++i) {
    const float s = map.total[i];
    scaled.data[i] = std::isnan(s) ? 0 : static_cast<std::uint8_t>(std::clamp(255.0 * s / saturation, 0.0, 255.0));
  }
  cv::Mat colored;
  cv::applyColorMap(scaled, colored, cv::COLORMAP_JET);  // BGR
  const bool have_obs = observed.width == map.width && observed.height == map.height;
  for (std::size_t i = 0; i < map.total.size(); ++i) {
    const std::uint8_t* bgr = colored.data + 3 * i;
    float grey = 128.0f;
    if (have_obs) grey = (observed.rgb[3 * i] + observed.rgb[3 * i + 1] + observed.rgb[3 * i + 2]) / 3.0f;
    if (std::isnan(map.total[i])) {
      for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<std::uint8_t>(0.5f * grey + 40.0f);
      continue;
    }
    for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<std::uint8_t>(0.35f * grey + 0.65f * bgr[2 - k]);
  }
  return out;
}

Status write_surprise_tiff(const std::filesystem::path& path, const SurpriseMap& map) {
  if (map.width == 0 || map.height == 0) return invalid_argument("'" + path.string() + "': empty surprise map");
  cv::Mat m(map.height, map.width, CV_32F, const_cast<float*>(map.total.data()));
  // OpenCV picks the format by the extension: the temporary file keeps ".tiff".
  return write_atomically(
      path,
      [&](const std::filesystem::path& tmp) -> Status {
        try {
          if (!cv::imwrite(tmp.string(), m)) return io_error("'" + path.string() + "': cannot write TIFF");
        } catch (const cv::Exception& e) {
          return io_error("'" + path.string() + "': cannot write TIFF: " + e.what());
        }
        return {};
      },
      ".tmp.tiff");
}

}  // namespace scenewatch::surprise
