#pragma once
/// RGB-D frames into organized clouds, intrinsics and trajectory files.
#include <filesystem>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// Metres per depth unit of the usual 16-bit depth images (millimetres: 7-Scenes, Kinect v1 drivers).
inline constexpr double kDepthMillimetres = 1e-3;
/// Metres per depth unit of the TUM RGB-D benchmark (1/5000 m).
inline constexpr double kDepthTum = 1.0 / 5000.0;

/// Back-projects a depth image with colour into an organized XYZRGB cloud in the camera frame
/// (x right, y down, z forward); a depth value d is d * depth_scale_m metres. Pixels with no
/// depth (0, or 65535 as 7-Scenes marks it) become NaN points. Errors: colour and depth sizes
/// differ, intrinsics invalid or for another image size, depth_scale_m not in (0, 1], no valid depth.
Result<CloudPtr> rgbd_to_cloud(const ColorImage& color, const DepthImage& depth, const Intrinsics& K,
                               double depth_scale_m = kDepthMillimetres, double max_depth_m = 10.0);

/// Reads a depth scale file: one number, the metres per depth unit (0.001 for millimetres,
/// 0.0001 for units of 0.1 mm). Errors name the file and, for a token that is no number, the line.
Result<double> read_depth_scale(const std::filesystem::path& path);
/// Checks a depth scale given on a command line or in a file: finite and in (0, 1] metres per unit.
Status validate_depth_scale(double depth_scale_m, const std::string& where);

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
/// Reads a TUM trajectory; '#' lines are comments. Errors name the file and the line.
Result<std::vector<StampedPose>> read_tum(const std::filesystem::path& path);
Status write_tum(const std::filesystem::path& path, const std::vector<StampedPose>& poses);

/// One line of a TUM image list (rgb.txt, depth.txt): "timestamp filename", the file relative to
/// the list's folder.
struct StampedFile {
  double stamp_s = 0.0;
  std::filesystem::path file;  ///< as written in the list
  int line = 0;                ///< its line number, for messages
};
/// Reads a TUM image list; '#' lines are comments. Errors name the file and the line: a timestamp
/// that is not a finite number, a line without a file name, an empty list.
Result<std::vector<StampedFile>> read_tum_list(const std::filesystem::path& path);
Status write_tum_list(const std::filesystem::path& path, const std::vector<StampedFile>& files);

}  // namespace scenewatch::io
