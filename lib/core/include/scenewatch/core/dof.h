#pragma once
/// The six degrees of freedom of a rigid motion in a support plane's frame (seed section 3.3):
/// shared by the simulator's ground truth and the foreground's learnt constraints.
#include <array>

#include "scenewatch/core/geometry.h"

namespace scenewatch {

enum class Dof { kX, kY, kZ, kRoll, kPitch, kYaw };
/// Number of DoFs of a rigid motion.
inline constexpr int kDofCount = 6;
/// Printable name ("x", "y", "z", "roll", "pitch", "yaw").
const char* to_string(Dof dof);
/// Values per DoF, indexed by static_cast<int>(Dof): metres for x y z, degrees for the angles.
using DofVector = std::array<double, kDofCount>;
/// A flag per DoF.
using DofFlags = std::array<bool, kDofCount>;

/// The motion from T_start to T of an object, as x y z (metres) and roll pitch yaw (degrees,
/// R_delta = Rz(yaw) Ry(pitch) Rx(roll) with R_delta = R(T) R(T_start)^T), in the support frame.
DofVector dof_delta(const Pose& T_world_support, const Pose& T_world_start, const Pose& T_world_object);

}  // namespace scenewatch
