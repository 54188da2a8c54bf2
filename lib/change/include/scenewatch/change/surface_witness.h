#pragma once
/// Which cameras have seen each surface of the map (issue 28). Several cameras feeding one model
/// never agree exactly on where a surface is: their poses come from separate sources (two
/// calibrations, two stretches of one reconstruction) and differ by centimetres. Interleaved, each
/// camera's frames then keep finding the other's version of a surface "seen through" or "in free
/// space". A camera therefore claims change only against surfaces it has seen itself; surfaces no
/// camera of this session has seen (a model loaded from disk) stay claimable by all, and a surface
/// another camera alone has seen waits for a camera that saw it. One camera: every surface is its
/// own, nothing changes. NOT thread safe: the working memory's writer owns it.
#include <cstdint>
#include <vector>

#include <tsl/robin_map.h>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::change {

class SurfaceWitness {
 public:
  enum class Seen { kByNone, kBySelf, kByOthersOnly };

  /// Surfaces are kept on a grid of the map's voxel edge; at most `max_voxels` of them (beyond,
  /// the ones seen least recently are forgotten, and become claimable by all again).
  explicit SurfaceWitness(double voxel_m = 0.02, std::size_t max_voxels = std::size_t{1} << 22);

  /// Records the surfaces of a frame (every `stride`-th pixel of every `stride`-th row of an
  /// organized cloud; every point of an unorganized one) as seen by `camera` (ids modulo 64).
  void witness(const Cloud& points_camera, const Pose& T_world_camera, std::uint32_t camera, int stride = 2);
  /// Who has seen the surface in the voxel of p, as far as `camera` is concerned; with
  /// `nearest_depth_m`, also the smallest depth any camera saw it at (0 when none did): the
  /// sensor's noise at that depth bounds where the map's surface lies.
  Seen seen(const Eigen::Vector3d& p_world, std::uint32_t camera, double* nearest_depth_m = nullptr) const;
  /// Surfaces written free or gone (a confirmed removal) are forgotten.
  void forget(const std::vector<Eigen::Vector3d>& points_world);

  std::size_t size() const { return voxels_.size(); }
  void reset() { voxels_.clear(); }

 private:
  struct Entry {
    std::uint64_t cameras = 0;  ///< bit (camera id mod 64) per camera that saw it
    std::uint64_t last_frame = 0;
    float nearest_depth_m = 0.0f;  ///< the smallest depth (camera z) it was seen at
  };
  std::uint64_t key(const Eigen::Vector3d& p) const;
  void prune();
  // The voxels the current frame has marked, by a hash of their key (surface_witness.cpp).
  struct Recent {
    std::uint64_t key = 0;
    std::uint64_t frame = 0;  ///< frames count from 1: 0 marks nothing
    float depth_m = 0.0f;
  };
  static constexpr std::size_t kRecent = 4096;
  std::vector<Recent> recent_;
  double per_m_;  ///< voxels per metre
  std::size_t max_voxels_;
  std::uint64_t frame_ = 0;
  tsl::robin_map<std::uint64_t, Entry, MixHash64> voxels_;
};

}  // namespace scenewatch::change
