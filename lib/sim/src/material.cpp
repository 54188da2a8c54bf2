#include "scenewatch/sim/material.h"

#include "texture_math.h"

namespace scenewatch::sim {

const char* to_string(TextureKind kind) {
  switch (kind) {
    case TextureKind::kNone: return "none";
    case TextureKind::kChecker: return "checker";
    case TextureKind::kStripes: return "stripes";
    case TextureKind::kNoise: return "noise";
    case TextureKind::kWood: return "wood";
  }
  return "unknown";
}

Eigen::Vector3d albedo(const Material& m, const Eigen::Vector3d& p) { return detail::albedo_inline(m, p); }

}  // namespace scenewatch::sim
