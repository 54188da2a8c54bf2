#pragma once
/// Image-based Bayesian surprise (seed D5.1, chapter 4, with the corrections of DESIGN.md).
///
/// Per pixel and channel, n <= 7 samples x_k from reference views give the mean mu and a Gamma
/// posterior over the precision: a = a0 + n/2, b = b0 + 1/2 sum (x_k - mu)^2. The observation
/// x_ob gives a' = a + 1/2, b' = b + 1/2 (x_ob - mu)^2. The surprise is
///   KL(Gamma(a', b') || Gamma(a, b))
///     = (a' - a) psi(a') - ln Gamma(a') + ln Gamma(a) + a (ln b' - ln b) + a' (b - b') / b'.
/// The seed's eq. (4.6) prints mu as a sum (it is the mean) and drops the -a' of the last term.
/// a and a' depend only on n, so with r = b / b' the per-pixel cost is one division and one log:
///   KL = C(n) - a ln r + a' (r - 1),  C(n) = psi(a') / 2 - ln Gamma(a') + ln Gamma(a).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace scenewatch::surprise {

/// Most reference samples per pixel (the seed's seven views).
constexpr int kMaxSamples = 7;

/// The three decoupled pathways of the seed (after Engel et al. 1997).
enum Channel { kLuminance = 0, kRedGreen = 1, kBlueYellow = 2 };
constexpr int kChannels = 3;
const char* channel_name(int channel);  ///< "luminance", "red_green", "blue_yellow"

/// Opponent signals of an 8-bit RGB colour, each in about [-1, 1]:
/// L = (R + G + B) / 3, RG = R - G, BY = B - (R + G) / 2, with R, G, B scaled to [0, 1].
inline void to_opponent(std::uint8_t r, std::uint8_t g, std::uint8_t b, float out[kChannels]) {
  constexpr float s = 1.0f / 255.0f;
  const float R = r * s, G = g * s, B = b * s;
  out[kLuminance] = (R + G + B) * (1.0f / 3.0f);
  out[kRedGreen] = R - G;
  out[kBlueYellow] = B - 0.5f * (R + G);
}
/// The inverse of to_opponent, in [0, 255] (not clamped).
void from_opponent(const float opp[kChannels], float rgb[3]);

/// Gamma prior over the precision (shape a0, rate b0). Its mean precision a0 / b0 is 1 / sigma0^2
/// for a colour noise sigma0 in opponent units (1/255 per grey level).
struct Prior {
  double a0 = 1.0;
  double b0 = 2.5e-4;  ///< sigma0 = 0.016, about 4 grey levels
};

/// KL(Gamma(a_p, b_p) || Gamma(a_q, b_q)) in nats, shape-rate parametrisation, closed form in
/// double precision (Boost.Math's lgamma and digamma).
double gamma_kl(double a_p, double b_p, double a_q, double b_q);

/// The surprise of one observation given its reference samples, in double precision: the
/// reference against which the fast kernel is tested. n must be in [1, kMaxSamples].
double bayesian_surprise(const double* samples, int n, double observed, const Prior& prior);

/// Natural logarithm for positive normal floats, branch-free so that loops over it vectorise
/// (Cephes' logf polynomial; error below 2 ulp on (0, inf)).
inline float fast_log(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const std::int32_t e0 = static_cast<std::int32_t>((bits >> 23) & 0xffu) - 126;  // x = m * 2^e, m in [0.5, 1)
  bits = (bits & 0x007fffffu) | 0x3f000000u;
  float m;
  std::memcpy(&m, &bits, sizeof m);
  // Cephes: bring m into [sqrt(1/2), sqrt(2)) and take log(1 + f) by a polynomial.
  // m < sqrt(1/2), compared on the bits (positive floats order like integers): a float compare
  // may trap on NaN, so GCC would keep a branch and not vectorise loops over this function.
  const float small = static_cast<float>(static_cast<std::int32_t>(bits < 0x3f3504f3u));
  const float fe = static_cast<float>(e0) - small;
  const float f = m + m * small - 1.0f;
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
  y += -2.12194440e-4f * fe;
  y += -0.5f * z;
  return f + y + 0.693359375f * fe;
}

/// The per-pixel surprise with the constants per n precomputed. Thread safe after construction.
class SurpriseKernel {
 public:
  /// Pixels with fewer than min_samples reference samples are unknown (NaN), not surprising.
  explicit SurpriseKernel(Prior prior = {}, int min_samples = 2);

  /// One channel over `count` pixels: per pixel the number of samples n, their mean and the sum of
  /// squared deviations from it, and the observed value; writes the KL in nats (NaN: unknown).
  void run(const std::uint8_t* n, const float* mean, const float* ssd, const float* observed, float* out,
           std::size_t count) const;
  /// `channels` channels at once (pointer arrays), also summing them into `total` when not null.
  void run_channels(int channels, const std::uint8_t* n, const float* const* mean, const float* const* ssd,
                    const float* const* observed, float* const* out, float* total, std::size_t count) const;
  /// The same for one pixel (float, fast log).
  float at(int n, float mean, float ssd, float observed) const;

  const Prior& prior() const { return prior_; }
  int min_samples() const { return min_samples_; }

 private:
  Prior prior_;
  int min_samples_;
  // Per n = 0..kMaxSamples: a, a' and C(n); valid[n] is 0 below min_samples.
  std::array<float, kMaxSamples + 1> a_{}, a1_{}, c_{}, valid_{};
  std::array<float, kMaxSamples + 1> cn_{};  ///< C(n), NaN below min_samples
};

}  // namespace scenewatch::surprise
