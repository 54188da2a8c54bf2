#pragma once
/// The background: an OctoMap ColorOcTree with free space from ray casting. OctoMap stays inside
/// this module; callers see points, boxes and states.
#include <filesystem>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"

namespace scenewatch::background {

struct Config {
  double resolution_m = 0.02;   ///< voxel edge
  double max_range_m = 5.0;     ///< rays are cut here; endpoints beyond are not occupied (<= 0: none)
  double prob_hit = 0.7;        ///< OctoMap sensor model
  double prob_miss = 0.4;
  double clamp_min = 0.12;
  double clamp_max = 0.97;
  /// true: batched ray casting from voxel-discretized endpoints (fast). false: OctoMap's plain
  /// insertPointCloud, one ray per point (the reference).
  bool fast_insertion = true;
  /// Fast insertion only: a ray is cast from its end back towards the sensor and stops after this
  /// many voxels in a row already freed by other rays of the frame (0: every ray to the sensor).
  int ray_stop_after = 32;
  /// The working memory's frames (organized, fast insertion): rays end at every Nth pixel of
  /// every Nth row, N at most this and at most what keeps the samples within one voxel of each
  /// other at max_range_m on a surface facing the camera (floor(resolution_m fx / max_range_m):
  /// 2 for a VGA Kinect at 2 cm and 5 m). 1: every pixel. insert() itself takes its stride.
  int insert_stride_px = 2;
};

/// Validates ranges; the message names the key (e.g. "background.resolution_m").
Status validate(const Config& config);

enum class Occupancy { kUnknown, kFree, kOccupied };
const char* to_string(Occupancy occupancy);

/// Summary of a box query.
struct BoxOccupancy {
  Occupancy state = Occupancy::kUnknown;  ///< occupied if any voxel is, else unknown if any is, else free
  std::size_t occupied_voxels = 0, free_voxels = 0, unknown_voxels = 0;  ///< at map resolution
};

/// A dense copy of part of the map at its finest resolution, aligned to its voxels: for
/// per-pixel and per-point lookups without octree searches (change detection).
struct DenseGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< min corner of voxel (0, 0, 0), world
  double resolution = 0.0;
  int nx = 0, ny = 0, nz = 0;
  std::vector<std::uint8_t> state;  ///< Occupancy per voxel, x fastest
  /// An occupied voxel's colour and belief. Occupied voxels are few in a frame's box (surfaces),
  /// so they are listed rather than stored per voxel.
  struct Surface {
    std::size_t index = 0;       ///< into state
    std::uint32_t rgb = 0;       ///< 0xRRGGBB
    std::uint8_t probability = 0;  ///< occupancy probability times 255
  };
  std::vector<Surface> occupied;  ///< every occupied voxel of the grid, by index
  /// Free voxels whose belief has not reached OctoMap's lower clamp yet (seen free a few times:
  /// not isNodeAtThreshold), by index, with their occupancy probability; no colour. Filled only
  /// on request (dense_grid() does; fill_dense_grid() when asked): the view planner counts their
  /// entropy, a settled free voxel carries none.
  std::vector<Surface> uncertain_free;
  std::size_t size() const { return state.size(); }
  /// Index of the voxel holding p, or -1 outside the grid.
  long index_of(const Eigen::Vector3d& p_world) const {
    const Eigen::Vector3d q = (p_world - origin) / resolution;
    const long i = static_cast<long>(std::floor(q.x())), j = static_cast<long>(std::floor(q.y())),
               k = static_cast<long>(std::floor(q.z()));
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return -1;
    return (k * ny + j) * nx + i;
  }
  Occupancy at(long index) const { return index < 0 ? Occupancy::kUnknown : static_cast<Occupancy>(state[index]); }
  Eigen::Vector3d center(long index) const {
    const long i = index % nx, j = (index / nx) % ny, k = index / (static_cast<long>(nx) * ny);
    return origin + resolution * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
};

struct InsertStats {
  std::size_t points = 0;          ///< valid points in the frame
  std::size_t occupied_updates = 0;
  std::size_t free_updates = 0;
};

/// Occupancy map of the static background. NOT thread safe: the owner serialises access.
class OccupancyMap {
 public:
  explicit OccupancyMap(const Config& config = {});
  ~OccupancyMap();
  OccupancyMap(OccupancyMap&&) noexcept;
  OccupancyMap& operator=(OccupancyMap&&) noexcept;

  /// Inserts a cloud given in the camera frame, placed with T_world_camera; rays start at the
  /// camera origin. Invalid points are skipped. `stride` > 1 (organized clouds, fast insertion
  /// only): only every stride-th pixel of every stride-th row ends a ray, for clouds whose pixels
  /// are much finer than a voxel (a VGA Kinect's are 1 cm apart at 5 m, a voxel 2 cm).
  InsertStats insert(const Cloud& points_camera, const Pose& T_world_camera, int stride = 1);

  Occupancy query(const Eigen::Vector3d& p_world) const;
  /// True when the last insert() cast a ray through the voxel of p (and did not end in it): the
  /// frame saw through that space, whatever the map's accumulated belief.
  bool freed_by_last_insert(const Eigen::Vector3d& p_world) const;
  BoxOccupancy query_box(const Aabb& box_world) const;
  /// Marks every known voxel in the box free (clamped), as octomap_server's clear_bbx does;
  /// unknown voxels stay unknown. Returns the number of voxels changed.
  std::size_t clear_box(const Aabb& box_world);
  void reset();

  /// The voxels overlapping a box as a dense grid, with its uncertain free voxels. Error when the
  /// box is invalid, outside the map's extent, or holds more than max_voxels voxels.
  Result<DenseGrid> dense_grid(const Aabb& box_world, std::size_t max_voxels = std::size_t{1} << 26) const;
  /// The same into `grid`, whose buffers are kept (a caller that fills one grid per frame
  /// allocates once); the uncertain free voxels only when asked. On error `grid` is unspecified.
  Status fill_dense_grid(const Aabb& box_world, DenseGrid& grid, std::size_t max_voxels = std::size_t{1} << 26,
                         bool with_uncertain_free = false) const;
  /// Sets the voxels holding the given points to the clamped free or occupied belief (a confirmed
  /// change written into the model at once instead of over several frames). kUnknown deletes
  /// them. Returns the number of distinct voxels set.
  std::size_t set_voxels(const std::vector<Eigen::Vector3d>& points_world, Occupancy state);

  /// .ot keeps colour; .bt keeps occupancy only. Written to a temporary file then renamed.
  Status save(const std::filesystem::path& path) const;
  /// Reads .ot (ColorOcTree or OcTree) or .bt; the resolution comes from the file.
  Status load(const std::filesystem::path& path);

  /// The tree as OctoMap's binary stream (OcTree::writeBinaryData: occupancy only, no header),
  /// the `data` of an octomap_msgs/Octomap with binary = true.
  std::string binary_data() const;
  /// Nodes of the tree, inner and leaves (what OcTree::size() says of a tree read from binary_data()).
  std::size_t num_nodes() const;

  double resolution() const;
  std::size_t num_leaf_nodes() const;
  std::size_t num_occupied_leaves() const;
  std::size_t memory_bytes() const;
  const Config& config() const { return config_; }

  /// Centres of occupied leaves (expanded to the finest resolution), for comparisons and export.
  std::vector<Eigen::Vector3d> occupied_voxel_centers() const;

 private:
  struct Impl;
  Config config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::background
