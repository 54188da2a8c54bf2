#pragma once
// Counter-based random numbers: every draw is a hash of (seed, stream, frame, pixel), so results do
// not depend on the order of evaluation and are the same bytes on every platform. std::
// distributions are avoided on purpose: their output is implementation-defined.
#include <cstdint>

namespace scenewatch::sim::detail {

/// SplitMix64's finaliser: a bijective 64-bit mix.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// 64 random bits for one (seed, a, b, c).
inline std::uint64_t hash(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return mix64(seed ^ mix64(a ^ mix64(b ^ mix64(c))));
}

/// The random bits of element `index` of a stream: SplitMix64 seeded by `stream_key` (itself a
/// hash), one mix per draw, for per-pixel loops.
inline std::uint64_t stream_bits(std::uint64_t stream_key, std::uint64_t index) {
  return mix64(stream_key + index * 0x9E3779B97F4A7C15ULL);
}

/// Uniform in [0, 1) from 24 bits.
inline double uniform24(std::uint64_t bits) { return static_cast<double>(bits & 0xFFFFFF) * (1.0 / 16777216.0); }

/// The 2^14 standard normal quantiles at (i + 0.5) / 2^14 (built once, thread-safe).
const float* gaussian_table();

/// Standard normal deviate from the low 14 bits (a quantile table: exact distribution up to
/// +-3.9 sigma, the same bytes on every platform). Hot loops hold gaussian_table() instead.
inline float gaussian14(std::uint64_t bits) { return gaussian_table()[bits & 0x3FFF]; }

}  // namespace scenewatch::sim::detail
