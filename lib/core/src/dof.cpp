// The DoFs of a rigid motion in a support frame.
#include "scenewatch/core/dof.h"

#include <algorithm>
#include <cmath>

namespace scenewatch {
namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
}  // namespace

const char* to_string(Dof dof) {
  switch (dof) {
    case Dof::kX: return "x";
    case Dof::kY: return "y";
    case Dof::kZ: return "z";
    case Dof::kRoll: return "roll";
    case Dof::kPitch: return "pitch";
    case Dof::kYaw: return "yaw";
  }
  return "unknown";
}

DofVector dof_delta(const Pose& T_world_support, const Pose& T_world_start, const Pose& T_world_object) {
  const Eigen::Matrix3d R_sw = T_world_support.linear().transpose();
  const Eigen::Vector3d dp = R_sw * (T_world_object.translation() - T_world_start.translation());
  const Eigen::Matrix3d R0 = R_sw * T_world_start.linear();
  const Eigen::Matrix3d R1 = R_sw * T_world_object.linear();
  const Eigen::Matrix3d D = R1 * R0.transpose();
  // ZYX Euler angles of D = Rz(yaw) Ry(pitch) Rx(roll).
  const double yaw = std::atan2(D(1, 0), D(0, 0));
  const double pitch = std::asin(std::clamp(-D(2, 0), -1.0, 1.0));
  const double roll = std::atan2(D(2, 1), D(2, 2));
  return {dp.x(), dp.y(), dp.z(), roll * kRadToDeg, pitch * kRadToDeg, yaw * kRadToDeg};
}

}  // namespace scenewatch
