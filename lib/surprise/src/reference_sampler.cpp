#include "reference_sampler.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::surprise {
namespace {

// The keyframe's pixel a projection's depth test reads, and the first of the four its colour does.
template <typename Ref, typename Projection>
std::size_t depth_pixel(const Ref& ref, const Projection& q) {
  return static_cast<std::size_t>(static_cast<int>(q.v + 0.5f)) * ref.width + static_cast<std::size_t>(q.u + 0.5f);
}
template <typename Ref, typename Projection>
std::size_t colour_pixel(const Ref& ref, const Projection& q) {
  return static_cast<std::size_t>(static_cast<int>(q.v)) * ref.width + static_cast<std::size_t>(q.u);
}

// One colour sample of a projection (z > 0); false when the reference does not see the point
// (occluded there). Always inlined into the sampling loop: GCC left it a call, which cost 1.2 ms
// per VGA frame.
template <typename Ref, typename Projection>
[[gnu::always_inline]] inline bool sample_projection(const Ref& ref, const Projection& q, float tol_m, float tol_rel,
                                                     float opp[kChannels]) {
  // Unoccluded: the keyframe's own depth at that pixel agrees with the point's depth in it.
  // Where the keyframe has no depth (glass, grazing surfaces) nothing refutes the sample.
  const std::uint16_t mm = ref.depth[depth_pixel(ref, q)];
  if (mm != 0 && mm != 65535 && std::abs(mm * 0.001f - q.z) > tol_m + tol_rel * q.z) return false;
  // Bilinear colour in 8-bit fixed-point weights: one conversion per channel, not four.
  const int u0 = static_cast<int>(q.u), v0 = static_cast<int>(q.v);
  const int wu = static_cast<int>((q.u - u0) * 256.0f), wv = static_cast<int>((q.v - v0) * 256.0f);
  const std::uint8_t* p00 = ref.rgb + 3 * colour_pixel(ref, q);
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
}

void store(ExpectedView& view, std::size_t i, int n, const float* sum, const float* sumsq) {
  view.count[i] = static_cast<std::uint8_t>(n);
  if (n == 0) return;
  const float inv = 1.0f / static_cast<float>(n);
  for (int c = 0; c < kChannels; ++c) {
    const float mean = sum[c] * inv;
    view.mean[c][i] = mean;
    view.ssd[c][i] = std::max(0.0f, sumsq[c] - sum[c] * mean);
  }
}

}  // namespace

ReferenceSampler::ReferenceSampler(const std::vector<std::shared_ptr<const background::Keyframe>>& references,
                                   const Pose& T_world_camera, const ExpectedViewConfig& config)
    : tol_m_(static_cast<float>(config.depth_tolerance_m)), tol_rel_(static_cast<float>(config.depth_tolerance_rel)) {
  const std::size_t wanted = static_cast<std::size_t>(std::min(config.max_samples, kMaxSamples));
  for (std::size_t r = 0; r < references.size() && refs_.size() < wanted; ++r) {
    const background::Keyframe& kf = *references[r];
    const Intrinsics& Kr = kf.intrinsics;
    if (kf.depth.width < 2 || kf.depth.height < 2) continue;
    const Eigen::Isometry3d T_ref_cam = kf.T_world_camera.inverse() * T_world_camera;
    Eigen::Matrix3d Kmat;
    Kmat << Kr.fx, 0, Kr.cx, 0, Kr.fy, Kr.cy, 0, 0, 1;
    refs_.push_back({(Kmat * T_ref_cam.linear()).cast<float>(), (Kmat * T_ref_cam.translation()).cast<float>(),
                     kf.depth.depth_mm.data(), kf.color.rgb.data(), kf.depth.width,
                     static_cast<float>(kf.depth.width - 1), static_cast<float>(kf.depth.height - 1)});
  }
}

// Straight-line arithmetic on arrays, which the compiler runs four points at a time.
void ReferenceSampler::project(const Ref& ref, const std::vector<float>& px, const std::vector<float>& py,
                               const std::vector<float>& pz, std::vector<Projection>& out) const {
  const float a00 = ref.A(0, 0), a01 = ref.A(0, 1), a02 = ref.A(0, 2), b0 = ref.b.x();
  const float a10 = ref.A(1, 0), a11 = ref.A(1, 1), a12 = ref.A(1, 2), b1 = ref.b.y();
  const float a20 = ref.A(2, 0), a21 = ref.A(2, 1), a22 = ref.A(2, 2), b2 = ref.b.z();
  for (std::size_t g = 0; g < px.size(); ++g) {
    const float x = px[g], y = py[g], z = pz[g];
    const float qx = a00 * x + a01 * y + a02 * z + b0;
    const float qy = a10 * x + a11 * y + a12 * z + b1;
    const float qz = a20 * x + a21 * y + a22 * z + b2;
    const float iz = 1.0f / qz;
    const float ur = qx * iz, vr = qy * iz;
    const bool seen = qz > 0.05f && ur >= 0.0f && vr >= 0.0f && ur < ref.umax && vr < ref.vmax;
    out[g] = Projection{seen ? ur : 0.0f, seen ? vr : 0.0f, seen ? qz : 0.0f};
  }
}

// One reference at a time: each reference's images are then read in order, which the caches
// follow; pixel by pixel, seven images read at once miss the cache on most reads. A reference's
// reads are projected first, then fetched 64 pixels ahead of their use: seven keyframes' images
// (10 MB at VGA) do not stay in the cache from frame to frame, and waiting for each read in turn
// cost most of the time (11.3 -> 7.5 ms per VGA frame).
void ReferenceSampler::sample(const std::vector<std::uint32_t>& pixels, const std::vector<float>& xn,
                              const std::vector<float>& yn, ExpectedView& view) const {
  const std::size_t np = pixels.size();
  const std::size_t w = static_cast<std::size_t>(view.width);
  std::vector<float> px(np), py(np), pz(np);  // the camera points, one array per coordinate
  for (std::size_t g = 0; g < np; ++g) {
    const float z = view.depth_m[pixels[g]];
    px[g] = xn[pixels[g] % w] * z;
    py[g] = yn[pixels[g] / w] * z;
    pz[g] = z;
  }
  std::vector<float> acc(np * 2 * kChannels, 0.0f);  // per pixel: sums then sums of squares
  std::vector<std::uint8_t> n(np, 0);
  std::vector<Projection> projections(np);
  constexpr std::size_t kAhead = 64;
  float opp[kChannels];
  // Copies the compiler can keep in registers (the sums written below might alias members).
  const float tol_m = tol_m_, tol_rel = tol_rel_;
  for (const Ref& ref_member : refs_) {
    const Ref ref = ref_member;
    project(ref, px, py, pz, projections);
    for (std::size_t g = 0; g < np; ++g) {
      if (g + kAhead < np && projections[g + kAhead].z > 0.0f) {
        const Projection& ahead = projections[g + kAhead];
        const std::uint8_t* c = ref.rgb + 3 * colour_pixel(ref, ahead);
        __builtin_prefetch(ref.depth + depth_pixel(ref, ahead));
        __builtin_prefetch(c);
        __builtin_prefetch(c + 3 * static_cast<std::size_t>(ref.width));
      }
      if (projections[g].z <= 0.0f || !sample_projection(ref, projections[g], tol_m, tol_rel, opp)) continue;
      float* a = &acc[g * 2 * kChannels];
      for (int c = 0; c < kChannels; ++c) {
        a[c] += opp[c];
        a[kChannels + c] += opp[c] * opp[c];
      }
      ++n[g];
    }
  }
  for (std::size_t g = 0; g < np; ++g) store(view, pixels[g], n[g], &acc[g * 2 * kChannels], &acc[g * 2 * kChannels + kChannels]);
}

}  // namespace scenewatch::surprise
