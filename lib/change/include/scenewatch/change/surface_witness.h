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

  std::size_t size() const { return live_; }
  void reset();

 private:
  // Voxels are kept in blocks of 4 x 4 x 4: a frame's neighbouring pixels mostly mark voxels of
  // one block, which is found once and then written in place (a hash lookup per voxel missed the
  // cache on most of them: the kitchen spent 55 % of the witness there). A block takes 1 KiB
  // (16 bytes a voxel); a surface crossing it fills a quarter of its voxels.
  static constexpr unsigned kBlockBits = 2;
  static constexpr unsigned kBlockVoxels = 1u << (3 * kBlockBits);
  struct Entry {
    std::uint64_t cameras = 0;  ///< bit (camera id mod 64) per camera that saw it; 0: not a surface
    std::uint32_t last_frame = 0;  ///< the frame count modulo 2^32
    float nearest_depth_m = 0.0f;  ///< the smallest depth (camera z) it was seen at
  };
  struct Block {
    Entry voxels[kBlockVoxels];
    std::uint32_t live = 0;  ///< entries with cameras != 0
  };
  /// A voxel as its block's key and its index inside the block.
  struct Where {
    std::uint64_t block = 0;
    unsigned voxel = 0;
  };
  Where where(const Eigen::Vector3d& p) const;
  Entry* find(const Where& w);
  const Entry* find(const Where& w) const { return const_cast<SurfaceWitness*>(this)->find(w); }
  std::uint32_t block_of(std::uint64_t block_key);  ///< found or added
  void clear(std::uint32_t block, unsigned voxel);
  void prune();
  // The voxels the current frame has marked, by a hash of their key (surface_witness.cpp).
  struct Recent {
    std::uint64_t key = 0;
    std::uint64_t frame = 0;  ///< frames count from 1: 0 marks nothing
    float depth_m = 0.0f;
  };
  static constexpr std::size_t kRecent = 4096;
  struct Mark {  ///< a voxel a frame marks (witness())
    std::uint32_t block;
    unsigned voxel;
    float depth_m;
  };
  std::vector<Mark> marks_;
  std::vector<Recent> recent_;
  double per_m_;  ///< voxels per metre
  std::size_t max_voxels_;
  std::uint64_t frame_ = 0;
  std::size_t live_ = 0;  ///< voxels seen by some camera
  tsl::robin_map<std::uint64_t, std::uint32_t, MixHash64> blocks_by_key_;
  std::vector<Block> blocks_;
  std::vector<std::uint64_t> block_keys_;
  std::vector<std::uint32_t> free_blocks_;
};

}  // namespace scenewatch::change
