#include <cmath>
#include <sstream>
#include <string>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/look_at.h"
#include "scenewatch/core/mesh.h"
#include "scenewatch/core/result.h"

namespace scenewatch {

const char* to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument: return "invalid_argument";
    case ErrorCode::kNotFound: return "not_found";
    case ErrorCode::kIoError: return "io_error";
    case ErrorCode::kPermissionDenied: return "permission_denied";
    case ErrorCode::kUnavailable: return "unavailable";
    case ErrorCode::kInternal: return "internal";
  }
  return "unknown";
}

const char* to_string(EventLevel level) {
  switch (level) {
    case EventLevel::kMismatch: return "MISMATCH";
    case EventLevel::kPrediction: return "PREDICTION";
    case EventLevel::kImplausibility: return "IMPLAUSIBILITY";
  }
  return "UNKNOWN";
}

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::kObjectAppeared: return "OBJECT_APPEARED";
    case EventKind::kObjectGone: return "OBJECT_GONE";
    case EventKind::kAppearanceChange: return "APPEARANCE_CHANGE";
    case EventKind::kObjectAdded: return "OBJECT_ADDED";
    case EventKind::kObjectRemoved: return "OBJECT_REMOVED";
    case EventKind::kObjectMoved: return "OBJECT_MOVED";
    case EventKind::kFrozenDofMotion: return "FROZEN_DOF_MOTION";
    case EventKind::kObjectPromoted: return "OBJECT_PROMOTED";
  }
  return "UNKNOWN";
}

Intrinsics centred_pinhole(int width, int height, double focal_px) {
  Intrinsics K;
  K.fx = K.fy = focal_px;
  K.cx = width / 2.0 - 0.5;
  K.cy = height / 2.0 - 0.5;
  K.width = width;
  K.height = height;
  return K;
}

Status validate_rigid(const Eigen::Matrix4d& m, double tolerance) {
  if (!m.allFinite()) return invalid_argument("pose has non-finite entries");
  const Eigen::RowVector4d last_row = m.row(3);
  if ((last_row - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > tolerance) {
    return invalid_argument("pose last row is not [0 0 0 1]");
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orthonormality = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality > tolerance) {
    std::ostringstream os;
    os << "pose is not rigid: rotation is not orthonormal (max |R^T R - I| = " << orthonormality << ")";
    return invalid_argument(os.str());
  }
  if (r.determinant() < 0) return invalid_argument("pose is not rigid: rotation is a reflection (det < 0)");
  return {};
}

Pose pose_from_matrix(const Eigen::Matrix4d& m) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Quaterniond(m.topLeftCorner<3, 3>()).normalized().toRotationMatrix();
  pose.translation() = m.topRightCorner<3, 1>();
  return pose;
}

Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up_world) {
  Eigen::Vector3d z = target - eye;
  if (z.norm() < 1e-12) z = Eigen::Vector3d::UnitX();
  z.normalize();
  // Image y points down: x = z x up keeps the world's up at the image's top.
  Eigen::Vector3d x = z.cross(up_world);
  if (x.norm() < 1e-9) x = z.cross(Eigen::Vector3d::UnitY());  // looking straight along up
  if (x.norm() < 1e-9) x = z.cross(Eigen::Vector3d::UnitX());
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Pose T = Pose::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

Aabb OrientedBox::aabb() const {
  const Eigen::Matrix3d r = rotation.toRotationMatrix();
  const Eigen::Vector3d half = 0.5 * (r.cwiseAbs() * extents);
  return {center - half, center + half};
}

void ColoredMesh::append(const ColoredMesh& other) {
  const auto offset = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  colors.insert(colors.end(), other.colors.begin(), other.colors.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const auto& t : other.triangles) triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

std::size_t count_valid(const Cloud& cloud) {
  std::size_t n = 0;
  for (const auto& p : cloud.points) n += is_valid(p) ? 1 : 0;
  return n;
}

}  // namespace scenewatch
