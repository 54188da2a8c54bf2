#include "scenewatch/surprise/expected_view.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::surprise {

Status validate(const ExpectedViewConfig& c) {
  if (c.max_samples < 1 || c.max_samples > kMaxSamples)
    return invalid_argument("surprise.max_samples must be in [1, " + std::to_string(kMaxSamples) + "]");
  if (!(c.depth_tolerance_m >= 0)) return invalid_argument("surprise.depth_tolerance_m must be >= 0");
  if (!(c.depth_tolerance_rel >= 0)) return invalid_argument("surprise.depth_tolerance_rel must be >= 0");
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
  std::array<std::vector<float>, kChannels> sum, sumsq;
  for (int c = 0; c < kChannels; ++c) {
    sum[c].assign(npix, 0.0f);
    sumsq[c].assign(npix, 0.0f);
  }
  std::vector<float> xn(static_cast<std::size_t>(K.width)), yn(static_cast<std::size_t>(K.height));
  for (int u = 0; u < K.width; ++u) xn[static_cast<std::size_t>(u)] = static_cast<float>((u - K.cx) / K.fx);
  for (int v = 0; v < K.height; ++v) yn[static_cast<std::size_t>(v)] = static_cast<float>((v - K.cy) / K.fy);

  const std::size_t used = std::min(references.size(), static_cast<std::size_t>(std::min(config.max_samples, kMaxSamples)));
  const float tol_m = static_cast<float>(config.depth_tolerance_m), tol_rel = static_cast<float>(config.depth_tolerance_rel);
  for (std::size_t r = 0; r < used; ++r) {
    const background::Keyframe& kf = *references[r];
    const Intrinsics& Kr = kf.intrinsics;
    const int rw = kf.depth.width, rh = kf.depth.height;
    if (rw < 2 || rh < 2) continue;
    ++view.reference_views;
    const Eigen::Isometry3d T_ref_cam = kf.T_world_camera.inverse() * T_world_camera;
    Eigen::Matrix3d Kmat = Eigen::Matrix3d::Identity();
    Kmat << Kr.fx, 0, Kr.cx, 0, Kr.fy, Kr.cy, 0, 0, 1;
    const Eigen::Matrix3f A = (Kmat * T_ref_cam.linear()).cast<float>();
    const Eigen::Vector3f b = (Kmat * T_ref_cam.translation()).cast<float>();
    const std::uint16_t* rdepth = kf.depth.depth_mm.data();
    const std::uint8_t* rgb = kf.color.rgb.data();
    const float umax = static_cast<float>(rw - 1), vmax = static_cast<float>(rh - 1);
    for (int v = 0; v < K.height; ++v) {
      const std::size_t row = static_cast<std::size_t>(v) * K.width;
      const Eigen::Vector3f base = A.col(1) * yn[static_cast<std::size_t>(v)] + A.col(2);
      for (int u = 0; u < K.width; ++u) {
        const std::size_t i = row + static_cast<std::size_t>(u);
        const float z = view.depth_m[i];
        if (z <= 0.0f) continue;
        const Eigen::Vector3f q = z * (A.col(0) * xn[static_cast<std::size_t>(u)] + base) + b;
        if (q.z() <= 0.05f) continue;
        const float iz = 1.0f / q.z();
        const float ur = q.x() * iz, vr = q.y() * iz;
        if (!(ur >= 0.0f && vr >= 0.0f && ur < umax && vr < vmax)) continue;
        // Unoccluded: the keyframe's own depth at that pixel agrees with the point's depth in it.
        const int ui = static_cast<int>(ur + 0.5f), vi = static_cast<int>(vr + 0.5f);
        // Where the keyframe has no depth (glass, grazing surfaces) nothing refutes the sample.
        const std::uint16_t mm = rdepth[static_cast<std::size_t>(vi) * rw + ui];
        if (mm != 0 && mm != 65535 && std::abs(mm * 0.001f - q.z()) > tol_m + tol_rel * q.z()) continue;
        // Bilinear colour.
        const int u0 = static_cast<int>(ur), v0 = static_cast<int>(vr);
        const float fu = ur - u0, fv = vr - v0;
        const std::uint8_t* p00 = rgb + 3 * (static_cast<std::size_t>(v0) * rw + u0);
        const std::uint8_t* p10 = p00 + 3;
        const std::uint8_t* p01 = p00 + 3 * static_cast<std::size_t>(rw);
        const std::uint8_t* p11 = p01 + 3;
        const float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
        constexpr float s = 1.0f / 255.0f;
        const float R = (w00 * p00[0] + w10 * p10[0] + w01 * p01[0] + w11 * p11[0]) * s;
        const float G = (w00 * p00[1] + w10 * p10[1] + w01 * p01[1] + w11 * p11[1]) * s;
        const float B = (w00 * p00[2] + w10 * p10[2] + w01 * p01[2] + w11 * p11[2]) * s;
        const float opp[kChannels] = {(R + G + B) * (1.0f / 3.0f), R - G, B - 0.5f * (R + G)};
        for (int c = 0; c < kChannels; ++c) {
          sum[c][i] += opp[c];
          sumsq[c][i] += opp[c] * opp[c];
        }
        ++view.count[i];
      }
    }
  }
  for (int c = 0; c < kChannels; ++c) {
    view.mean[c].assign(npix, 0.0f);
    view.ssd[c].assign(npix, 0.0f);
    for (std::size_t i = 0; i < npix; ++i) {
      const int n = view.count[i];
      if (n == 0) continue;
      const float mean = sum[c][i] / n;
      view.mean[c][i] = mean;
      view.ssd[c][i] = std::max(0.0f, sumsq[c][i] - sum[c][i] * mean);
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

}  // namespace scenewatch::surprise
