#pragma once
// Procedural textures as inline functions, so that the ray caster's per-pixel loop can inline
// them; material.cpp exposes the same code as sim::albedo.
#include <cmath>
#include <cstdint>
#include <utility>

#include "scenewatch/sim/material.h"

namespace scenewatch::sim::detail {


/// Permutation and lattice values of the value noise: a fixed table (Perlin's construction),
/// the same on every platform.
struct NoiseTable {
  std::uint8_t perm[512];
  float value[256];
  NoiseTable() {
    std::uint64_t state = 0x2545F4914F6CDD1DULL;
    auto next = [&state]() {
      state ^= state >> 12;
      state ^= state << 25;
      state ^= state >> 27;
      return state * 0x2545F4914F6CDD1DULL;
    };
    std::uint8_t p[256];
    for (int i = 0; i < 256; ++i) p[i] = static_cast<std::uint8_t>(i);
    for (int i = 255; i > 0; --i) std::swap(p[i], p[next() % static_cast<std::uint64_t>(i + 1)]);
    for (int i = 0; i < 512; ++i) perm[i] = p[i & 255];
    for (int i = 0; i < 256; ++i) value[i] = static_cast<float>(next() >> 40) * (1.0f / 16777216.0f);
  }
};

inline const NoiseTable& noise_table() {
  static const NoiseTable table;
  return table;
}

inline float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

/// floor() without a library call (valid far beyond any scene coordinate / texture scale).
inline double fast_floor(double x) {
  const auto i = static_cast<std::int64_t>(x);
  return static_cast<double>(x < static_cast<double>(i) ? i - 1 : i);
}

/// Trilinear value noise in [0, 1) with unit lattice spacing (period 256).
inline float value_noise(const Eigen::Vector3d& p) {
  const NoiseTable& T = noise_table();
  const double fx = fast_floor(p.x()), fy = fast_floor(p.y()), fz = fast_floor(p.z());
  const int ix = static_cast<int>(static_cast<std::int64_t>(fx) & 255);
  const int iy = static_cast<int>(static_cast<std::int64_t>(fy) & 255);
  const int iz = static_cast<int>(static_cast<std::int64_t>(fz) & 255);
  const float tx = smooth(static_cast<float>(p.x() - fx));
  const float ty = smooth(static_cast<float>(p.y() - fy));
  const float tz = smooth(static_cast<float>(p.z() - fz));
  auto v = [&](int x, int y, int z) { return T.value[T.perm[T.perm[T.perm[x] + y] + z]]; };
  const int x1 = (ix + 1) & 255, y1 = (iy + 1) & 255, z1 = (iz + 1) & 255;
  const float a = v(ix, iy, iz) + tx * (v(x1, iy, iz) - v(ix, iy, iz));
  const float b = v(ix, y1, iz) + tx * (v(x1, y1, iz) - v(ix, y1, iz));
  const float c = v(ix, iy, z1) + tx * (v(x1, iy, z1) - v(ix, iy, z1));
  const float d = v(ix, y1, z1) + tx * (v(x1, y1, z1) - v(ix, y1, z1));
  const float ab = a + ty * (b - a);
  const float cd = c + ty * (d - c);
  return ab + tz * (cd - ab);
}

/// One-dimensional value noise in [0, 1) (two lookups): cheap enough for surfaces as large as a
/// table top.
inline float value_noise_1d(double x) {
  const NoiseTable& T = noise_table();
  const double fx = fast_floor(x);
  const int i = static_cast<int>(static_cast<std::int64_t>(fx) & 255);
  const float t = smooth(static_cast<float>(x - fx));
  const float a = T.value[T.perm[i]], b = T.value[T.perm[i + 1]];
  return a + t * (b - a);
}

/// Checker parity of a point: 0 or 1.
inline double checker_mix(const Eigen::Vector3d& p, double inv) {
  const auto parity = static_cast<std::int64_t>(fast_floor(p.x() * inv + 1e-6)) +
                      static_cast<std::int64_t>(fast_floor(p.y() * inv + 1e-6)) +
                      static_cast<std::int64_t>(fast_floor(p.z() * inv + 1e-6));
  return (parity & 1) ? 1.0 : 0.0;
}

/// Wood grain along x: bands across y that waver slowly along x.
inline double wood_mix(const Eigen::Vector3d& p, double inv) {
  const double n = value_noise_1d(p.x() * 0.3 * inv + 0.37 * p.y() * inv);
  const double ring = (p.y() * inv + 0.5 * n) * 3.0;
  const double f = std::abs(2.0 * (ring - fast_floor(ring)) - 1.0);
  return f * f * f * 0.8 + 0.2 * n;
}

/// Share of the second colour at a point (0: color, 1: color2); returned in a register.
inline double texture_mix(const Material& m, const Eigen::Vector3d& p) {
  const double inv = 1.0 / m.scale_m;
  switch (m.texture) {
    case TextureKind::kNone: return 0.0;
    case TextureKind::kChecker: return checker_mix(p, inv);
    case TextureKind::kStripes: return (static_cast<std::int64_t>(fast_floor(p.z() * inv)) & 1) ? 1.0 : 0.0;
    case TextureKind::kNoise: return value_noise(p * inv);
    case TextureKind::kWood: return wood_mix(p, inv);
  }
  return 0.0;
}

/// Albedo (RGB, 0..255) of a material at a point in the object's local frame.
inline Eigen::Vector3d albedo_inline(const Material& m, const Eigen::Vector3d& p) {
  if (m.texture == TextureKind::kNone) return m.color;
  return m.color + texture_mix(m, p) * (m.color2 - m.color);
}

}  // namespace scenewatch::sim::detail
