#include "scenewatch/sim/hand.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Pose key_pose(const HandKey& k) {
  Pose T = Pose::Identity();
  T.linear() = rotation_from_rpy_deg(k.roll_deg, k.pitch_deg, k.yaw_deg);
  T.translation() = k.position_world;
  return T;
}

}  // namespace

HandSpec::HandSpec() {
  skin.color = Eigen::Vector3d(226, 176, 146);
  skin.color2 = Eigen::Vector3d(205, 150, 122);
  skin.texture = TextureKind::kNoise;
  skin.scale_m = 0.02;
}

HandPart capsule_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) {
  HandPart part;
  part.shape.kind = ShapeKind::kCapsule;
  part.shape.radius_m = r;
  const Eigen::Vector3d axis = b - a;
  part.shape.height_m = axis.norm();
  const Eigen::Vector3d z = axis.normalized();
  part.T_hand_part.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z).toRotationMatrix();
  part.T_hand_part.translation() = a - r * z;  // the capsule's local origin is the bottom of its cap
  return part;
}

std::vector<HandPart> hand_parts(double s) {
  using V = Eigen::Vector3d;
  std::vector<HandPart> parts;
  // Palm: two capsules side by side, about 8 cm wide and 3 cm thick.
  parts.push_back(capsule_between(s * V(-0.035, -0.018, 0), s * V(0.035, -0.018, 0), s * 0.016));
  parts.push_back(capsule_between(s * V(-0.035, 0.018, 0), s * V(0.035, 0.018, 0), s * 0.016));
  // Four fingers, slightly curled towards the palm side (-z).
  for (double y : {-0.027, -0.009, 0.009, 0.027}) {
    const double len = y > 0.02 ? 0.055 : (std::abs(y) < 0.01 ? 0.075 : 0.068);
    parts.push_back(capsule_between(s * V(0.05, y, 0), s * V(0.05 + len, y, -0.015), s * 0.0085));
  }
  // Thumb.
  parts.push_back(capsule_between(s * V(-0.005, 0.035, -0.005), s * V(0.045, 0.06, -0.025), s * 0.0105));
  // Forearm from the wrist to the elbow.
  parts.push_back(capsule_between(s * V(-0.055, 0, 0), s * V(-0.33, 0, 0.0), s * 0.033));
  return parts;
}

Eigen::Matrix3d rotation_from_rpy_deg(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Pose hand_pose(const HandSpec& hand, double frame) {
  const auto& keys = hand.keys;
  if (keys.empty()) return Pose::Identity();
  if (frame <= keys.front().frame) return key_pose(keys.front());
  if (frame >= keys.back().frame) return key_pose(keys.back());
  std::size_t i = 1;
  while (i < keys.size() && keys[i].frame < frame) ++i;
  const HandKey& a = keys[i - 1];
  const HandKey& b = keys[i];
  const double span = b.frame - a.frame;
  double s = span > 0 ? std::clamp((frame - a.frame) / span, 0.0, 1.0) : 1.0;
  s = s * s * (3.0 - 2.0 * s);
  const Eigen::Quaterniond qa(rotation_from_rpy_deg(a.roll_deg, a.pitch_deg, a.yaw_deg));
  const Eigen::Quaterniond qb(rotation_from_rpy_deg(b.roll_deg, b.pitch_deg, b.yaw_deg));
  Pose T = Pose::Identity();
  T.linear() = qa.slerp(s, qb).toRotationMatrix();
  T.translation() = a.position_world + s * (b.position_world - a.position_world);
  return T;
}

}  // namespace scenewatch::sim
