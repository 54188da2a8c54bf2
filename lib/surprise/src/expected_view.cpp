#include "scenewatch/surprise/expected_view.h"

#include <algorithm>
#include <cmath>

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

// Fills runs of missing depth along one line (stride apart) no longer than max_gap whose two ends
// agree within tolerance, by linear interpolation: the holes glass and grazing angles leave in
// every keyframe's depth, which would otherwise leave the surface behind them without samples.
void fill_line(float* d, int n, std::ptrdiff_t stride, int max_gap, float rel) {
  int last = -1;
  for (int i = 0; i < n; ++i) {
    const float z = d[i * stride];
    if (z <= 0.0f) continue;
    if (last >= 0 && i - last > 1 && i - last - 1 <= max_gap) {
      const float z0 = d[last * stride];
      if (std::abs(z - z0) <= rel * std::min(z, z0)) {
        for (int k = last + 1; k < i; ++k) d[k * stride] = z0 + (z - z0) * static_cast<float>(k - last) / static_cast<float>(i - last);
      }
    }
    last = i;
  }
}

void fill_depth_holes(std::vector<float>* depth, int w, int h, const ExpectedViewConfig& config) {
  const int max_gap = static_cast<int>(std::lround(config.fill_holes_px * w / 640.0));
  if (max_gap <= 0) return;
  const float rel = static_cast<float>(config.fill_holes_max_jump);
  std::vector<float> horizontal = *depth;
  for (int v = 0; v < h; ++v) fill_line(horizontal.data() + static_cast<std::size_t>(v) * w, w, 1, max_gap, rel);
  for (int u = 0; u < w; ++u) fill_line(depth->data() + u, h, w, max_gap, rel);
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

  // Per reference: the projection of a point of this camera, q = A p + b (pixel coordinates times
  // depth in the reference), and its images.
  struct Ref {
    Eigen::Matrix3f A;
    Eigen::Vector3f b;
    const std::uint16_t* depth;
    const std::uint8_t* rgb;
    int width;
    float umax, vmax;
  };
  std::vector<Ref> refs;
  const std::size_t wanted = static_cast<std::size_t>(std::min(config.max_samples, kMaxSamples));
  for (std::size_t r = 0; r < references.size() && refs.size() < wanted; ++r) {
    const background::Keyframe& kf = *references[r];
    const Intrinsics& Kr = kf.intrinsics;
    if (kf.depth.width < 2 || kf.depth.height < 2) continue;
    const Eigen::Isometry3d T_ref_cam = kf.T_world_camera.inverse() * T_world_camera;
    Eigen::Matrix3d Kmat;
    Kmat << Kr.fx, 0, Kr.cx, 0, Kr.fy, Kr.cy, 0, 0, 1;
    refs.push_back({(Kmat * T_ref_cam.linear()).cast<float>(), (Kmat * T_ref_cam.translation()).cast<float>(),
                    kf.depth.depth_mm.data(), kf.color.rgb.data(), kf.depth.width,
                    static_cast<float>(kf.depth.width - 1), static_cast<float>(kf.depth.height - 1)});
  }
  view.reference_views = refs.size();

  const float tol_m = static_cast<float>(config.depth_tolerance_m), tol_rel = static_cast<float>(config.depth_tolerance_rel);
  // One colour sample of camera point p from one reference, in opponent signals; false when the
  // reference does not see p (outside, behind, or occluded there).
  const auto sample_ref = [&](const Ref& ref, const Eigen::Vector3f& p, float opp[kChannels]) {
    const Eigen::Vector3f q = ref.A * p + ref.b;
    if (q.z() <= 0.05f) return false;
    const float iz = 1.0f / q.z();
    const float ur = q.x() * iz, vr = q.y() * iz;
    if (!(ur >= 0.0f && vr >= 0.0f && ur < ref.umax && vr < ref.vmax)) return false;
    // Unoccluded: the keyframe's own depth at that pixel agrees with the point's depth in it.
    // Where the keyframe has no depth (glass, grazing surfaces) nothing refutes the sample.
    const int ui = static_cast<int>(ur + 0.5f), vi = static_cast<int>(vr + 0.5f);
    const std::uint16_t mm = ref.depth[static_cast<std::size_t>(vi) * ref.width + ui];
    if (mm != 0 && mm != 65535 && std::abs(mm * 0.001f - q.z()) > tol_m + tol_rel * q.z()) return false;
    // Bilinear colour in 8-bit fixed-point weights: one conversion per channel, not four.
    const int u0 = static_cast<int>(ur), v0 = static_cast<int>(vr);
    const int wu = static_cast<int>((ur - u0) * 256.0f), wv = static_cast<int>((vr - v0) * 256.0f);
    const std::uint8_t* p00 = ref.rgb + 3 * (static_cast<std::size_t>(v0) * ref.width + u0);
    const std::uint8_t* p10 = p00 + 3;
    const std::uint8_t* p01 = p00 + 3 * static_cast<std::size_t>(ref.width);
    const std::uint8_t* p11 = p01 + 3;
    const int w00 = (256 - wu) * (256 - wv), w10 = wu * (256 - wv), w01 = (256 - wu) * wv, w11 = wu * wv;
    constexpr float s = 1.0f / (255.0f * 65536.0f);
    const float R = static_cast<float>(w00 * p00[0] + w10 * p10[0] + w01 * p01[0] + w11 * p11[0]) * s;
    const float G = static_cast<float>(w00 * p00[1] + w10 * p10[1] + w01 * p01[1] + w11 * p11[1]) * s;
    const float B = static_cast<float>(w00 * p00[2] + w10 * p10[2] + w01 * p01[2] + w11 * p11[2]) * s;
    opp[kLuminance] = (R + G + B) * (1.0f / 3.0f);
    opp[kRedGreen] = R - G;
    opp[kBlueYellow] = B - 0.5f * (R + G);
    return true;
  };
  const auto camera_point = [&](std::size_t i, int u, int v) {
    const float z = view.depth_m[i];
    return Eigen::Vector3f(xn[static_cast<std::size_t>(u)] * z, yn[static_cast<std::size_t>(v)] * z, z);
  };
  const auto store = [&](std::size_t i, int n, const float* sum, const float* sumsq) {
    view.count[i] = static_cast<std::uint8_t>(n);
    if (n == 0) return;
    const float inv = 1.0f / static_cast<float>(n);
    for (int c = 0; c < kChannels; ++c) {
      const float mean = sum[c] * inv;
      view.mean[c][i] = mean;
      view.ssd[c][i] = std::max(0.0f, sumsq[c] - sum[c] * mean);
    }
  };
  const auto sample_pixel = [&](std::size_t i, int u, int v) {
    const Eigen::Vector3f p = camera_point(i, u, v);
    float sum[kChannels] = {0, 0, 0}, sumsq[kChannels] = {0, 0, 0}, opp[kChannels];
    int n = 0;
    for (const Ref& ref : refs) {
      if (!sample_ref(ref, p, opp)) continue;
      for (int c = 0; c < kChannels; ++c) {
        sum[c] += opp[c];
        sumsq[c] += opp[c] * opp[c];
      }
      ++n;
    }
    store(i, n, sum, sumsq);
  };

  // Samples on a grid of `step` pixels, one reference at a time (each reference's images are
  // then read in order, which the caches and prefetchers follow; pixel by pixel, seven images
  // read at once miss the cache on most reads). The pixels between take their grid anchor's
  // statistics when they lie on the same surface (depths agree), else they are sampled themselves.
  const int step = std::max(1, static_cast<int>(std::lround(config.sample_step_px * K.width / 640.0)));
  const int w = K.width, h = K.height;
  {
    std::vector<std::uint32_t> grid;  // pixels of the grid with an expected surface
    for (int v = 0; v < h; v += step) {
      for (int u = 0; u < w; u += step) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (view.depth_m[i] > 0.0f) grid.push_back(static_cast<std::uint32_t>(i));
      }
    }
    std::vector<Eigen::Vector3f> points(grid.size());
    for (std::size_t g = 0; g < grid.size(); ++g) {
      const int u = static_cast<int>(grid[g] % static_cast<std::uint32_t>(w)), v = static_cast<int>(grid[g] / static_cast<std::uint32_t>(w));
      points[g] = camera_point(grid[g], u, v);
    }
    std::vector<float> acc(grid.size() * 2 * kChannels, 0.0f);  // per grid pixel: sums then sums of squares
    std::vector<std::uint8_t> n(grid.size(), 0);
    float opp[kChannels];
    for (const Ref& ref : refs) {
      for (std::size_t g = 0; g < grid.size(); ++g) {
        if (!sample_ref(ref, points[g], opp)) continue;
        float* a = &acc[g * 2 * kChannels];
        for (int c = 0; c < kChannels; ++c) {
          a[c] += opp[c];
          a[kChannels + c] += opp[c] * opp[c];
        }
        ++n[g];
      }
    }
    for (std::size_t g = 0; g < grid.size(); ++g) store(grid[g], n[g], &acc[g * 2 * kChannels], &acc[g * 2 * kChannels + kChannels]);
  }
  if (step > 1) {
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
          sample_pixel(i, u, v);
        }
      }
    }
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
    view.count[i] = 1;
    for (int c = 0; c < kChannels; ++c) {
      view.mean[static_cast<std::size_t>(c)][i] = opponent[c];
      view.ssd[static_cast<std::size_t>(c)][i] = 0.0f;
    }
    ++changed;
  }
  return changed;
}

}  // namespace scenewatch::surprise
