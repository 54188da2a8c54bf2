// Frame validation: what a frame from outside must be before the pipeline takes it.
#include "scenewatch/io/frame_validation.h"

#include <cmath>
#include <sstream>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::io {

namespace {

// Farther than any depth sensor sees (lidars reach a few hundred metres).
constexpr float kMaxPointRangeM = 1000.0f;
// A camera's name is a label (a serial number, a topic, "head"), not a text.
constexpr std::size_t kMaxCameraName = 128;

std::string metres(double m) {
  std::ostringstream os;
  os << m << " m";
  return os.str();
}

Status validate_camera_name(const std::string& name, const std::string& where) {
  if (name.size() > kMaxCameraName) {
    return invalid_argument(where + ": camera name is " + std::to_string(name.size()) + " bytes long, at most " +
                            std::to_string(kMaxCameraName) + " are allowed");
  }
  for (unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) return invalid_argument(where + ": camera name contains a control character");
  }
  return {};
}

}  // namespace

// One pass over the cloud serves both the checks and the count of valid points. The
// camera and every point must lie within `workspace_radius_m` of the world origin: a pose at 1e30
// is finite and rigid, and would put objects, keyframes and a mesh there (OctoMap alone drops
// such points without a word).
Result<std::size_t> validate_frame(const Frame& f, double workspace_radius_m) {
  const std::string where = f.source.empty() ? std::string("frame") : "frame from '" + f.source + "'";
  const std::string workspace = "outside the workspace (workspace.radius_m: " + metres(workspace_radius_m) +
                                " around the world origin)";
  if (!f.cloud || f.cloud->empty()) return invalid_argument(where + ": cloud is empty");
  if (f.cloud->width * f.cloud->height != f.cloud->size()) {
    return invalid_argument(where + ": cloud width x height (" + std::to_string(f.cloud->width) + "x" +
                            std::to_string(f.cloud->height) + ") does not match its " + std::to_string(f.cloud->size()) + " points");
  }
  if (f.T_world_camera) {
    if (auto st = validate_rigid(f.T_world_camera->matrix()); !st) return invalid_argument(where + ": " + st.error().message);
    const double camera_m = f.T_world_camera->translation().norm();
    if (camera_m > workspace_radius_m) {
      return invalid_argument(where + ": the camera pose lies " + metres(camera_m) + " from the world origin, " + workspace);
    }
  }
  // Finite is not enough: a point at 3e38 m would be ray-cast through the map. No depth sensor
  // sees that far; such coordinates are not metres (wrong units, garbage).
  const Pose T = f.pose_or_identity();
  const double workspace_squared = workspace_radius_m * workspace_radius_m;
  std::size_t valid = 0, far = 0, outside = 0;
  const PointT* first_far = nullptr;
  Eigen::Vector3d first_outside = Eigen::Vector3d::Zero();
  // A rigid motion moves a point at most by the camera's distance from the origin: a point nearer
  // to the camera than the workspace radius less that distance lies inside (with a margin for
  // rounding), and only the others are moved into the world to be checked.
  const double camera_m = T.translation().norm();
  const double inside_m = workspace_radius_m - camera_m;
  const float surely_inside_squared = inside_m > 0 ? static_cast<float>(inside_m * inside_m * (1.0 - 1e-5)) : -1.0f;
  for (const auto& p : f.cloud->points) {
    if (!is_valid(p)) continue;
    ++valid;
    const float range_squared = p.getVector3fMap().squaredNorm();
    if (range_squared > kMaxPointRangeM * kMaxPointRangeM && far++ == 0) first_far = &p;
    if (range_squared < surely_inside_squared) continue;
    const Eigen::Vector3d p_world = T * p.getVector3fMap().cast<double>();
    if (p_world.squaredNorm() > workspace_squared && outside++ == 0) first_outside = p_world;
  }
  if (valid == 0) return invalid_argument(where + ": no valid points (all NaN or non-finite)");
  if (far > 0) {
    return invalid_argument(where + ": " + std::to_string(far) + " points lie farther than " +
                            std::to_string(static_cast<int>(kMaxPointRangeM)) + " m from the sensor (the first at " +
                            std::to_string(first_far->x) + " " + std::to_string(first_far->y) + " " +
                            std::to_string(first_far->z) + "): coordinates must be metres in the camera frame");
  }
  if (outside > 0) {
    std::ostringstream at;
    at << first_outside.x() << " " << first_outside.y() << " " << first_outside.z();
    return invalid_argument(where + ": " + std::to_string(outside) + " points lie " + workspace + " (the first at " +
                            at.str() + " in the world)");
  }
  if (!std::isfinite(f.stamp_s)) return invalid_argument(where + ": stamp is not finite");
  if (auto st = validate_camera_name(f.camera, where); !st) return st.error();
  if (f.intrinsics) {
    const Intrinsics& K = *f.intrinsics;
    if (!K.valid()) return invalid_argument(where + ": intrinsics are invalid");
    if (f.cloud->height > 1 && (static_cast<int>(f.cloud->width) != K.width || static_cast<int>(f.cloud->height) != K.height)) {
      return invalid_argument(where + ": intrinsics are for " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                              ", the organized cloud is " + std::to_string(f.cloud->width) + "x" + std::to_string(f.cloud->height));
    }
  }
  return valid;
}

}  // namespace scenewatch::io
