#pragma once
/// Poses, intrinsics and boxes. Poses are T_a_b: they map coordinates in frame b to frame a.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch {

using Pose = Eigen::Isometry3d;

/// Pinhole intrinsics of a depth camera, in pixels.
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  /// True when focal lengths are positive and the image size is set.
  bool valid() const { return fx > 0 && fy > 0 && width > 0 && height > 0; }
};

/// A pinhole of the given size and focal length (pixels), its principal point at the image centre.
Intrinsics centred_pinhole(int width, int height, double focal_px);

/// Checks that a 4x4 matrix is finite, rigid (orthonormal rotation, det +1) and has last row
/// [0 0 0 1]. The message names what is wrong.
Status validate_rigid(const Eigen::Matrix4d& m, double tolerance = 1e-3);

/// Builds a pose from a validated 4x4 matrix, re-orthonormalising the rotation.
Pose pose_from_matrix(const Eigen::Matrix4d& m);

/// Axis-aligned box in some frame.
struct Aabb {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  bool valid() const { return (min.array() <= max.array()).all() && min.allFinite() && max.allFinite(); }
  Eigen::Vector3d center() const { return 0.5 * (min + max); }
  bool contains(const Eigen::Vector3d& p) const { return (p.array() >= min.array()).all() && (p.array() <= max.array()).all(); }
  bool overlaps(const Aabb& o) const { return (min.array() <= o.max.array()).all() && (o.min.array() <= max.array()).all(); }
  /// Larger by `margin` on every side.
  Aabb grown(double margin) const { return {(min.array() - margin).matrix(), (max.array() + margin).matrix()}; }
  /// The smallest box holding both.
  Aabb united(const Aabb& o) const { return {min.cwiseMin(o.min), max.cwiseMax(o.max)}; }
};

/// Oriented box: centre, rotation of the box axes in the frame, full side lengths.
struct OrientedBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d extents = Eigen::Vector3d::Zero();
  /// The axis-aligned box that encloses this one.
  Aabb aabb() const;
  /// True when p lies inside the box grown by `margin` on every side.
  bool contains(const Eigen::Vector3d& p, double margin = 0.0) const {
    const Eigen::Vector3d q = rotation.conjugate() * (p - center);
    return (q.cwiseAbs().array() <= 0.5 * extents.array() + margin).all();
  }
};

}  // namespace scenewatch
