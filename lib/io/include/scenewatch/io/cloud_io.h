#pragma once
/// Reading and writing point clouds: PCD (ascii, binary, binary_compressed) and PLY, through
/// PCL's readers, with validation that names the file and the problem.
#include <filesystem>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/mesh.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// A cloud as read from a file.
struct CloudFile {
  CloudPtr cloud;            ///< XYZRGB; colour is grey (128) when the file had none
  bool has_color = false;    ///< the file had an rgb or rgba field
  bool organized = false;    ///< height > 1
  std::size_t valid_points = 0;
  Eigen::Vector3d sensor_origin = Eigen::Vector3d::Zero();  ///< PCD VIEWPOINT translation
};

/// Reads a .pcd or .ply file (by extension). Fields beyond x y z rgb/rgba (such as label) are
/// ignored. Errors: missing file, truncated data, header that disagrees with the data, missing
/// x/y/z fields, zero valid points (all NaN or non-finite).
Result<CloudFile> read_cloud(const std::filesystem::path& path);

/// Reads only the label field of a PCD (mOSD ground truth); error when there is none.
Result<std::vector<std::uint32_t>> read_pcd_labels(const std::filesystem::path& path);

/// Writes a binary PCD (x y z rgb). Written to a temporary file and renamed into place.
Status write_pcd(const std::filesystem::path& path, const Cloud& cloud);

/// Writes a binary PLY point cloud (vertices x y z and colour, no faces). Atomic like write_pcd.
Status write_ply(const std::filesystem::path& path, const Cloud& cloud);

/// Writes a binary PLY mesh with per-vertex colour (opens in MeshLab, CloudCompare, Open3D).
Status write_mesh_ply(const std::filesystem::path& path, const ColoredMesh& mesh);
/// Reads a PLY triangle mesh (vertex colour when present, else black).
Result<ColoredMesh> read_mesh_ply(const std::filesystem::path& path);

}  // namespace scenewatch::io
