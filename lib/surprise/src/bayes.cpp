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

float fast_log(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  int e = static_cast<int>((bits >> 23) & 0xffu) - 126;  // x = m * 2^e, m in [0.5, 1)
  bits = (bits & 0x007fffffu) | 0x3f000000u;
  float m;
  std::memcpy(&m, &bits, sizeof m);
  // Cephes: bring m into [sqrt(1/2), sqrt(2)) and take log(1 + f) by a polynomial.
  const bool small = m < 0.707106781186547524f;
  e -= small ? 1 : 0;
  const float f = small ? (m + m - 1.0f) : (m - 1.0f);
  const float z = f * f;
  float y = 7.0376836292e-2f;
  y = y * f - 1.1514610310e-1f;
  y = y * f + 1.1676998740e-1f;
  y = y * f - 1.2420140846e-1f;
  y = y * f + 1.4249322787e-1f;
  y = y * f - 1.6668057665e-1f;
  y = y * f + 2.0000714765e-1f;
  y = y * f - 2.4999993993e-1f;
  y = y * f + 3.3333331174e-1f;
  y = y * f * z;
  const float fe = static_cast<float>(e);
  y += -2.12194440e-4f * fe;
  y += -0.5f * z;
  return f + y + 0.693359375f * fe;
}

SurpriseKernel::SurpriseKernel(Prior prior, int min_samples) : prior_(prior), min_samples_(min_samples) {
  for (int n = 0; n <= kMaxSamples; ++n) {
    const double a = prior.a0 + 0.5 * n, a1 = a + 0.5;
    a_[n] = static_cast<float>(a);
    a1_[n] = static_cast<float>(a1);
    c_[n] = static_cast<float>(0.5 * boost::math::digamma(a1) - boost::math::lgamma(a1) + boost::math::lgamma(a));
    valid_[n] = (n >= std::max(1, min_samples)) ? 1.0f : 0.0f;
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
  const float b0 = static_cast<float>(prior_.b0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < count; ++i) {
    const int k = n[i] > kMaxSamples ? kMaxSamples : n[i];
    const float b = b0 + 0.5f * ssd[i];
    const float d = observed[i] - mean[i];
    const float r = b / (b + 0.5f * d * d);
    const float kl = c_[k] - a_[k] * fast_log(r) + a1_[k] * (r - 1.0f);
    out[i] = valid_[k] != 0.0f ? kl : nan;
  }
}

}  // namespace scenewatch::surprise
