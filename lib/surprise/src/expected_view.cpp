#include "scenewatch/surprise/expected_view.h"

#include <algorithm>
#include <cmath>

#include "reference_sampler.h"

namespace scenewatch::surprise {

Status validate(const ExpectedViewConfig& c) {
  if (c.max_samples < 1 || c.max_samples > kMaxSamples)
    return invalid_argument("surprise.max_samples must be in [1, " + std::to_string(kMaxSamples) + "]");
  if (!(c.depth_tolerance_m >= 0)) return invalid_argument("surprise.depth_tolerance_m must be >= 0");
  if (!(c.depth_tolerance_rel >= 0)) return invalid_argument("surprise.depth_tolerance_rel must be >= 0");
  if (c.sample_step_px < 1 || c.sample_step_px > 16) return invalid_argument("surprise.sample_step_px must be in [1, 16]");
  if (c.fill_holes_px < 0 || c.fill_holes_px > 640) return invalid_argument("surprise.fill_holes_px must be in [0, 640]");
  if (!(c.fill_holes_max_jump >= 0)) return invalid_argument("surprise.fill_holes_max_jump must be >= 0");
  return {};
}

namespace {

// Fills the gap between the depths d[0] and d[n * stride], n steps apart along a line of
// `stride`-apart values, when it is no longer than max_gap and its two ends agree within
// tolerance, by linear interpolation: the holes glass and grazing angles leave in every keyframe's
// depth, which would otherwise leave the surface behind them without samples.
void fill_gap(float* d, std::ptrdiff_t stride, int n, int max_gap, float rel) {
  if (n <= 1 || n - 1 > max_gap) return;
  const float z0 = d[0], z = d[n * stride];
  if (std::abs(z - z0) > rel * std::min(z, z0)) return;
  for (int k = 1; k < n; ++k) d[k * stride] = z0 + (z - z0) * static_cast<float>(k) / static_cast<float>(n);
}

void fill_depth_holes(std::vector<float>* depth, int w, int h, const ExpectedViewConfig& config) {
  const int max_gap = static_cast<int>(std::lround(config.fill_holes_px * w / 640.0));
  if (max_gap <= 0) return;
  const float rel = static_cast<float>(config.fill_holes_max_jump);
  std::vector<float> horizontal = *depth;
  for (int v = 0; v < h; ++v) {
    float* row = horizontal.data() + static_cast<std::size_t>(v) * w;
    int last = -1;
    for (int u = 0; u < w; ++u) {
      if (row[u] <= 0.0f) continue;
      if (last >= 0) fill_gap(row + last, 1, u - last, max_gap, rel);
      last = u;
    }
  }
  // The columns row by row (a column at a time would read a new cache line at every pixel):
  // each column remembers its last row with depth, and a gap is filled when it closes.
  float* d = depth->data();
  std::vector<int> last(static_cast<std::size_t>(w), -1);
  for (int v = 0; v < h; ++v) {
    const float* row = d + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      if (row[u] <= 0.0f) continue;
      const int l = last[static_cast<std::size_t>(u)];
      if (l >= 0) fill_gap(d + static_cast<std::size_t>(l) * w + u, w, v - l, max_gap, rel);
      last[static_cast<std::size_t>(u)] = v;
    }
  }
  // A pixel filled both ways takes the nearer surface; filled one way, that one.
  for (std::size_t i = 0; i < depth->size(); ++i) {
    const float a = horizontal[i], b = (*depth)[i];
    if (a > 0.0f && (b <= 0.0f || a < b)) (*depth)[i] = a;
  }
}

}  // namespace

ExpectedView render_expected_view(const background::AppearanceMemory& memory, const Pose& T_world_camera,
                                  const Intrinsics& K, const ExpectedViewConfig& config) {
  const std::size_t n = static_cast<std::size_t>(std::max(config.max_samples, memory.config().depth_views));
  auto refs = memory.nearest(T_world_camera, n);
  const std::size_t depth_views = std::min(refs.size(), static_cast<std::size_t>(memory.config().depth_views));
  const background::DepthMap depth = memory.render_depth(
      T_world_camera, K, {refs.begin(), refs.begin() + static_cast<std::ptrdiff_t>(depth_views)});
  if (refs.size() > static_cast<std::size_t>(config.max_samples)) refs.resize(static_cast<std::size_t>(config.max_samples));
  return sample_expected_view(depth, refs, T_world_camera, K, config);
}

ExpectedView sample_expected_view(const background::DepthMap& depth,
                                  const std::vector<std::shared_ptr<const background::Keyframe>>& references,
                                  const Pose& T_world_camera, const Intrinsics& K, const ExpectedViewConfig& config) {
  ExpectedView view;
  view.width = K.width;
  view.height = K.height;
  view.T_world_camera = T_world_camera;
  view.intrinsics = K;
  const std::size_t npix = view.pixel_count();
  view.depth_m = depth.depth_m;
  view.depth_m.resize(npix, 0.0f);
  fill_depth_holes(&view.depth_m, K.width, K.height, config);
  view.count.assign(npix, 0);
  std::vector<float> xn(static_cast<std::size_t>(K.width)), yn(static_cast<std::size_t>(K.height));
  for (int u = 0; u < K.width; ++u) xn[static_cast<std::size_t>(u)] = static_cast<float>((u - K.cx) / K.fx);
  for (int v = 0; v < K.height; ++v) yn[static_cast<std::size_t>(v)] = static_cast<float>((v - K.cy) / K.fy);
  for (int c = 0; c < kChannels; ++c) {
    view.mean[c].assign(npix, 0.0f);
    view.ssd[c].assign(npix, 0.0f);
  }

  const ReferenceSampler sampler(references, T_world_camera, config);
  view.reference_views = sampler.size();
  const float tol_m = static_cast<float>(config.depth_tolerance_m), tol_rel = static_cast<float>(config.depth_tolerance_rel);

  // Samples on a grid of `step` pixels. The pixels between take their grid anchor's statistics
  // when they lie on the same surface (depths agree), else they are sampled themselves.
  const int step = std::max(1, static_cast<int>(std::lround(config.sample_step_px * K.width / 640.0)));
  const int w = K.width, h = K.height;
  std::vector<std::uint32_t> pixels;
  for (int v = 0; v < h; v += step) {
    for (int u = 0; u < w; u += step) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (view.depth_m[i] > 0.0f) pixels.push_back(static_cast<std::uint32_t>(i));
    }
  }
  sampler.sample(pixels, xn, yn, view);
  if (step > 1) {
    pixels.clear();
    for (int v = 0; v < h; ++v) {
      const int va = v - v % step;
      for (int u = 0; u < w; ++u) {
        if (v == va && u % step == 0) continue;
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const float z = view.depth_m[i];
        if (z <= 0.0f) continue;
        const std::size_t a = static_cast<std::size_t>(va) * w + static_cast<std::size_t>(u - u % step);
        const float za = view.depth_m[a];
        if (za > 0.0f && std::abs(za - z) <= tol_m + tol_rel * z) {
          view.count[i] = view.count[a];
          for (int c = 0; c < kChannels; ++c) {
            view.mean[c][i] = view.mean[c][a];
            view.ssd[c][i] = view.ssd[c][a];
          }
        } else {
          pixels.push_back(static_cast<std::uint32_t>(i));
        }
      }
    }
    sampler.sample(pixels, xn, yn, view);
  }
  return view;
}

ColorImage expected_color(const ExpectedView& view) {
  ColorImage img;
  img.width = view.width;
  img.height = view.height;
  img.rgb.assign(3 * view.pixel_count(), 0);
  for (std::size_t i = 0; i < view.pixel_count(); ++i) {
    if (view.count[i] == 0) continue;
    const float opp[kChannels] = {view.mean[0][i], view.mean[1][i], view.mean[2][i]};
    float rgb[3];
    from_opponent(opp, rgb);
    for (int k = 0; k < 3; ++k) img.rgb[3 * i + k] = static_cast<std::uint8_t>(std::clamp(std::lround(rgb[k]), 0L, 255L));
  }
  return img;
}

std::size_t splat_surface(ExpectedView& view, const KnownSurface& surface, double tolerance_m) {
  if (view.width <= 0 || view.height <= 0 || !(surface.spacing_m > 0) || view.depth_m.size() != view.pixel_count() ||
      view.count.size() != view.pixel_count())
    return 0;
  const Pose T_camera_world = view.T_world_camera.inverse();
  const Intrinsics& K = view.intrinsics;
  float opponent[kChannels];
  to_opponent(static_cast<std::uint8_t>(std::clamp(surface.rgb.x(), 0.0f, 255.0f)),
              static_cast<std::uint8_t>(std::clamp(surface.rgb.y(), 0.0f, 255.0f)),
              static_cast<std::uint8_t>(std::clamp(surface.rgb.z(), 0.0f, 255.0f)), opponent);
  // Each opponent signal is a linear map of RGB, so its variance is m' C m; the map's columns are
  // to_opponent's answers for pure red, green and blue (per 255 units).
  Eigen::Matrix3f to_opp;
  for (int k = 0; k < 3; ++k) {
    float column[kChannels];
    to_opponent(k == 0 ? 255 : 0, k == 1 ? 255 : 0, k == 2 ? 255 : 0, column);
    to_opp.col(k) = Eigen::Vector3f(column[0], column[1], column[2]) / 255.0f;
  }
  const Eigen::Matrix3f opp_covariance = to_opp * surface.rgb_covariance * to_opp.transpose();
  float ssd[kChannels];
  for (int c = 0; c < kChannels; ++c) ssd[c] = kMaxSamples * std::max(0.0f, opp_covariance(c, c));
  // The splat's depth first (nearest point per pixel), then what it changes.
  std::vector<float> splat(view.pixel_count(), 0.0f);
  for (const Eigen::Vector3d& p_world : surface.points_world) {
    const Eigen::Vector3d p = T_camera_world * p_world;
    if (!(p.z() > 0.05)) continue;
    const double u = K.fx * p.x() / p.z() + K.cx, v = K.fy * p.y() / p.z() + K.cy;
    const int half = std::max(0, static_cast<int>(std::ceil(0.5 * surface.spacing_m * K.fx / p.z())));
    const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
    for (int y = std::max(0, v0 - half); y <= std::min(view.height - 1, v0 + half); ++y)
      for (int x = std::max(0, u0 - half); x <= std::min(view.width - 1, u0 + half); ++x) {
        float& z = splat[static_cast<std::size_t>(y) * view.width + x];
        if (z <= 0.0f || p.z() < z) z = static_cast<float>(p.z());
      }
  }
  std::size_t changed = 0;
  for (std::size_t i = 0; i < splat.size(); ++i) {
    const float z = splat[i];
    if (z <= 0.0f) continue;
    const float expected = view.depth_m[i];
    if (expected > 0.0f && z >= expected - static_cast<float>(tolerance_m)) continue;
    view.depth_m[i] = z;
    view.count[i] = kMaxSamples;
    for (int c = 0; c < kChannels; ++c) {
      view.mean[static_cast<std::size_t>(c)][i] = opponent[c];
      view.ssd[static_cast<std::size_t>(c)][i] = ssd[c];
    }
    ++changed;
  }
  return changed;
}

}  // namespace scenewatch::surprise
