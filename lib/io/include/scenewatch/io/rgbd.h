#pragma once
/// RGB-D frames into organized clouds, intrinsics and trajectory files.
#include <filesystem>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// Back-projects a depth image (mm) with colour into an organized XYZRGB cloud in the camera
/// frame (x right, y down, z forward). Pixels with no depth become NaN points. Errors: colour
/// and depth sizes differ, intrinsics invalid or for another image size, no valid depth.
Result<CloudPtr> rgbd_to_cloud(const ColorImage& color, const DepthImage& depth, const Intrinsics& K,
                               double max_depth_m = 10.0);

/// Recovers pinhole intrinsics from an organized cloud in its camera frame by least squares on
/// u = fx x/z + cx and v = fy y/z + cy over its valid points. Error when the cloud is not
/// organized, has too few valid points, or is not a pinhole projection (residual over 0.5 px).
Result<Intrinsics> estimate_intrinsics(const Cloud& organized);

/// Reads a 3x3 camera matrix (whitespace separated, as 7-Scenes' camera-intrinsics.txt); width
/// and height are left 0 for the caller to fill from the images.
Result<Intrinsics> read_intrinsics(const std::filesystem::path& path);
/// Writes the 3x3 camera matrix in the same format.
Status write_intrinsics(const std::filesystem::path& path, const Intrinsics& K);

/// Reads a 4x4 camera-to-world matrix (one row per line) and checks that it is rigid.
Result<Pose> read_pose_matrix(const std::filesystem::path& path);
Status write_pose_matrix(const std::filesystem::path& path, const Pose& T_world_camera);

/// One line of a TUM trajectory: "t tx ty tz qx qy qz qw", T_world_camera.
struct StampedPose {
  double stamp_s = 0.0;
  Pose T_world_camera = Pose::Identity();
};
/// Reads a TUM trajectory; '#' lines are comments. Errors name the line number.
Result<std::vector<StampedPose>> read_tum(const std::filesystem::path& path);
Status write_tum(const std::filesystem::path& path, const std::vector<StampedPose>& poses);

}  // namespace scenewatch::io
