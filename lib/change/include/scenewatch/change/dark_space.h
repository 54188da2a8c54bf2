#pragma once
/// Space the sensor looked into and got nothing back from (issue 28: the seed's removed glasses).
///
/// A structured-light camera returns no depth from clear glass: its rays pass the glass and the
/// pattern is lost, so a glass is a hole in every frame and never enters the map. The space it
/// fills stays unknown while the space around it is seen free, and the surface behind it (the
/// table) is known from other views. DarkSpace remembers those voxels: unknown voxels of the map
/// that rays without a return crossed on their way to a surface the map holds, well in front of
/// it. A voxel is dark once rays from at least `min_frames` frames and two distinct directions
/// crossed it (a reflection or a dark patch is a hole from one direction, not from all).
///
/// When a later frame's rays return from beyond dark voxels, passing through them, whatever
/// filled them is gone: the change detection takes those voxels as evidence of a removal, as it
/// takes the map's own surfaces that a frame sees through (mismatch.h). Unknown space nobody looked into
/// (behind furniture, inside objects) is never dark: no ray without a return reached a known
/// surface through it. NOT thread safe: the working memory's writer owns it.
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

#include <tsl/robin_map.h>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::change {

struct Config;
struct DepthView;

class DarkSpace {
 public:
  /// Voxels on a grid of the map's edge; at most `max_voxels` are kept (beyond, those not
  /// crossed for the longest are forgotten).
  explicit DarkSpace(double voxel_m = 0.02, std::size_t max_voxels = std::size_t{1} << 20);

  /// Records the rays of this frame's pixels without depth (off the image border; every few
  /// pixels) against the map before the frame (`grid`, around the frame's points): the unknown
  /// voxels each crossed before the first surface the map holds along it, more than the
  /// tolerance in front of that surface. A ray that meets no surface within change.max_range_m
  /// records nothing (a window, the open room), nor one whose surface lies nearer or farther
  /// than any depth `camera` has returned so far (beyond the noise): the sensor's own range
  /// explains that hole.
  void record(const background::DenseGrid& grid, const DepthView& depth, const Pose& T_world_camera, const Config& config,
              std::uint32_t camera);

  /// A recorded voxel inside `grid` and not occupied there, for the change detection to ask
  /// whether the frame sees through it (mismatch.h).
  struct Voxel {
    std::uint64_t key = 0;
    Eigen::Vector3d center_world = Eigen::Vector3d::Zero();
    /// Dark (rays without a return crossed it in at least min_frames frames, from two
    /// directions, `camera`'s among them) and never seen through before it last was: what
    /// filled it stood in every view until now. Seen through now, it is gone.
    bool dark = false;
  };
  /// The recorded voxels that are not mixed (seen through, then crossed dark again: air in front
  /// of something, or a reflection that comes and goes), inside `grid` and not occupied there.
  std::vector<Voxel> in_grid(const background::DenseGrid& grid, std::uint32_t camera, int min_frames) const;
  /// The frame sees through the voxel `key` (from in_grid()).
  void seen_through(std::uint64_t key);
  /// Forgets the voxels holding these points (a confirmed removal: what filled them is gone).
  void forget(const std::vector<Eigen::Vector3d>& points_world);

  /// Voxels recorded (dark or not yet).
  std::size_t size() const { return voxels_.size(); }
  /// Voxels that are dark by in_grid()'s rule for `min_frames`.
  std::size_t dark_voxels(int min_frames) const;
  void reset();

 private:
  struct Entry {
    std::uint64_t cameras = 0;     ///< bit (camera id mod 64) per camera whose rays crossed it
    std::uint32_t last_frame = 0;  ///< record() calls, modulo 2^32
    std::uint16_t frames = 0;      ///< frames whose rays crossed it (saturating)
    bool two_views = false;        ///< crossed from directions kDistinctViewDeg apart
    bool seen_through = false;     ///< a frame saw through it (mismatch.h's footprint test)
    bool mixed = false;            ///< crossed dark after it was seen through: never dark
    float first_dir[3] = {0, 0, 0};  ///< the direction of the first ray that crossed it
  };
  std::uint64_t key(const Eigen::Vector3d& p) const;
  static std::uint64_t block_of(std::uint64_t voxel_key);  ///< its block of 8 x 8 x 8 voxels
  void erase(std::uint64_t voxel_key);
  void prune();

  struct Range {  ///< the nearest and farthest depth a camera has returned
    double min_m = std::numeric_limits<double>::infinity();
    double max_m = 0.0;
  };
  std::map<std::uint32_t, Range> ranges_;
  double per_m_;
  std::size_t max_voxels_;
  std::uint32_t frame_ = 0;
  tsl::robin_map<std::uint64_t, Entry, MixHash64> voxels_;
  tsl::robin_map<std::uint64_t, std::vector<std::uint64_t>, MixHash64> blocks_;  ///< voxel keys by block
};

}  // namespace scenewatch::change
