#include "scenewatch/sim/camera_path.h"

#include <algorithm>
#include <cmath>

#include "random.h"

namespace scenewatch::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr std::uint64_t kStreamShake = 11;

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

/// A smooth random signal in about [-1, 1]: a sum of three sinusoids with seeded phases.
double shake_signal(std::uint64_t seed, std::uint64_t channel, double t) {
  double sum = 0.0;
  for (std::uint64_t k = 0; k < 3; ++k) {
    const std::uint64_t bits = detail::hash(seed, kStreamShake, channel, k);
    const double phase = detail::uniform24(bits) * 2.0 * M_PI;
    const double freq = 0.05 + 0.25 * detail::uniform24(bits >> 24);  // cycles per frame
    sum += std::sin(2.0 * M_PI * freq * t + phase) / (1.0 + k);
  }
  return sum / 1.8333;
}

}  // namespace

const char* to_string(CameraPathKind kind) {
  switch (kind) {
    case CameraPathKind::kStatic: return "static";
    case CameraPathKind::kCircle: return "circle";
    case CameraPathKind::kHandheld: return "handheld";
    case CameraPathKind::kKeyframes: return "keyframes";
  }
  return "unknown";
}

Pose camera_pose(const CameraPath& path, double frame, int frame_count, std::uint64_t seed) {
  const double u = frame_count > 1 ? frame / (frame_count - 1) : 0.0;
  switch (path.kind) {
    case CameraPathKind::kStatic:
      return look_at(path.position_world, path.target_world);
    case CameraPathKind::kCircle: {
      const double angle = (path.start_deg + u * path.arc_deg) * kDegToRad;
      const double wobble = path.wobble_m * std::sin(2.0 * M_PI * path.wobble_cycles * u);
      const double r = path.radius_m + wobble;
      const Eigen::Vector3d eye(path.target_world.x() + r * std::cos(angle),
                                path.target_world.y() + r * std::sin(angle), path.height_m + 0.5 * wobble);
      return look_at(eye, path.target_world);
    }
    case CameraPathKind::kHandheld: {
      Eigen::Vector3d dp, dr;
      for (std::uint64_t k = 0; k < 3; ++k) {
        dp[k] = path.shake_m * shake_signal(seed, k, frame);
        dr[k] = path.shake_deg * kDegToRad * shake_signal(seed, 3 + k, frame);
      }
      Pose T = look_at(path.position_world + dp, path.target_world);
      if (dr.norm() > 0) T.linear() = T.linear() * Eigen::AngleAxisd(dr.norm(), dr.normalized()).toRotationMatrix();
      return T;
    }
    case CameraPathKind::kKeyframes: {
      const auto& keys = path.keys;
      if (keys.empty()) return look_at(path.position_world, path.target_world);
      if (frame <= keys.front().frame) return look_at(keys.front().position_world, keys.front().target_world);
      if (frame >= keys.back().frame) return look_at(keys.back().position_world, keys.back().target_world);
      std::size_t i = 1;
      while (i < keys.size() && keys[i].frame < frame) ++i;
      const CameraKey& a = keys[i - 1];
      const CameraKey& b = keys[i];
      const double span = b.frame - a.frame;
      const double s = span > 0 ? smoothstep(std::clamp((frame - a.frame) / span, 0.0, 1.0)) : 1.0;
      return look_at(a.position_world + s * (b.position_world - a.position_world),
                     a.target_world + s * (b.target_world - a.target_world));
    }
  }
  return Pose::Identity();
}

}  // namespace scenewatch::sim
