#include "scenewatch/surprise/bayes.h"

#include <boost/math/special_functions/digamma.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <algorithm>
#include <cstring>
#include <limits>

namespace scenewatch::surprise {

const char* channel_name(int channel) {
  switch (channel) {
    case kLuminance: return "luminance";
    case kRedGreen: return "red_green";
    case kBlueYellow: return "blue_yellow";
  }
  return "unknown";
}

void from_opponent(const float opp[kChannels], float rgb[3]) {
  const float L = opp[kLuminance], RG = opp[kRedGreen], BY = opp[kBlueYellow];
  // From 3L = R+G+B and BY = B - (R+G)/2: R+G = 2L - 2BY/3, B = L + 2BY/3.
  const float rpg = 2.0f * L - 2.0f * BY / 3.0f;
  const float B = L + 2.0f * BY / 3.0f;
  rgb[0] = 255.0f * 0.5f * (rpg + RG);
  rgb[1] = 255.0f * 0.5f * (rpg - RG);
  rgb[2] = 255.0f * B;
}

double gamma_kl(double a_p, double b_p, double a_q, double b_q) {
  using boost::math::digamma;
  using boost::math::lgamma;
  return (a_p - a_q) * digamma(a_p) - lgamma(a_p) + lgamma(a_q) + a_q * (std::log(b_p) - std::log(b_q)) +
         a_p * (b_q - b_p) / b_p;
}

double bayesian_surprise(const double* samples, int n, double observed, const Prior& prior) {
  double mu = 0;
  for (int k = 0; k < n; ++k) mu += samples[k];
  mu /= n;
  double ssd = 0;
  for (int k = 0; k < n; ++k) ssd += (samples[k] - mu) * (samples[k] - mu);
  const double a = prior.a0 + 0.5 * n, b = prior.b0 + 0.5 * ssd;
  const double a1 = a + 0.5, b1 = b + 0.5 * (observed - mu) * (observed - mu);
  return gamma_kl(a1, b1, a, b);
}

SurpriseKernel::SurpriseKernel(Prior prior, int min_samples) : prior_(prior), min_samples_(min_samples) {
  for (int n = 0; n <= kMaxSamples; ++n) {
    const double a = prior.a0 + 0.5 * n, a1 = a + 0.5;
    a_[n] = static_cast<float>(a);
    a1_[n] = static_cast<float>(a1);
    c_[n] = static_cast<float>(0.5 * boost::math::digamma(a1) - boost::math::lgamma(a1) + boost::math::lgamma(a));
    valid_[n] = (n >= std::max(1, min_samples)) ? 1.0f : 0.0f;
    cn_[n] = valid_[n] != 0.0f ? c_[n] : std::numeric_limits<float>::quiet_NaN();
  }
}

float SurpriseKernel::at(int n, float mean, float ssd, float observed) const {
  if (n < 0 || n > kMaxSamples || valid_[n] == 0.0f) return std::numeric_limits<float>::quiet_NaN();
  const float b = static_cast<float>(prior_.b0) + 0.5f * ssd;
  const float d = observed - mean;
  const float r = b / (b + 0.5f * d * d);
  return c_[n] - a_[n] * fast_log(r) + a1_[n] * (r - 1.0f);
}

void SurpriseKernel::run(const std::uint8_t* n, const float* mean, const float* ssd, const float* observed,
                         float* out, std::size_t count) const {
  const float* means[kChannels] = {mean, nullptr, nullptr};
  const float* ssds[kChannels] = {ssd, nullptr, nullptr};
  const float* obs[kChannels] = {observed, nullptr, nullptr};
  float* outs[kChannels] = {out, nullptr, nullptr};
  run_channels(1, n, means, ssds, obs, outs, nullptr, count);
}

// Compiled twice, for AVX2 + FMA and for the x86-64 baseline (SSE2); the loader picks the clone the
// CPU supports (GCC function multi-versioning), so the binary stays portable.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2,fma", "default")))
#endif
void SurpriseKernel::run_channels(int channels, const std::uint8_t* n, const float* const* mean, const float* const* ssd,
                                  const float* const* observed, float* const* out, float* total,
                                  std::size_t count) const {
  // Blocks: the constants per pixel are gathered once (scalar), then each channel is one
  // branch-free arithmetic loop the compiler vectorises. An unknown pixel has C = NaN, which the
  // arithmetic carries into the result.
  constexpr std::size_t kBlock = 512;
  alignas(32) float a[kBlock], a1[kBlock], c[kBlock];
  const float b0 = static_cast<float>(prior_.b0);
  for (std::size_t start = 0; start < count; start += kBlock) {
    const std::size_t len = std::min(kBlock, count - start);
    for (std::size_t i = 0; i < len; ++i) {
      const int k = std::min<int>(n[start + i], kMaxSamples);
      a[i] = a_[k];
      a1[i] = a1_[k];
      c[i] = cn_[k];
    }
    for (int ch = 0; ch < channels; ++ch) {
      const float* mu = mean[ch] + start;
      const float* s = ssd[ch] + start;
      const float* x = observed[ch] + start;
      float* o = out[ch] + start;
      for (std::size_t i = 0; i < len; ++i) {
        const float b = b0 + 0.5f * s[i];
        const float d = x[i] - mu[i];
        const float r = b / (b + 0.5f * d * d);
        o[i] = c[i] - a[i] * fast_log(r) + a1[i] * (r - 1.0f);
      }
      if (total) {
        float* t = total + start;
        if (ch == 0) {
          for (std::size_t i = 0; i < len; ++i) t[i] = o[i];
        } else {
          for (std::size_t i = 0; i < len; ++i) t[i] += o[i];
        }
      }
    }
  }
}

}  // namespace scenewatch::surprise
