#pragma once
/// The appearance memory of the background: keyframes (colour, depth, pose, intrinsics) kept when a
/// view is new enough, within a budget, and the textured mesh triangulated from their depth. The
/// mesh renders the expected depth at any pose; the keyframes give the view-dependent colour
/// samples of the seed's image database (D5.1 section 4.2).
///
/// Mesh: each keyframe contributes one patch, a grid triangulation of its depth image at a stride
/// (edges across depth jumps are cut), with the keyframe's colour per vertex. Patches are
/// independent, so evicting a keyframe removes exactly its patch. The expected depth at a pose is
/// the z-buffer of the patches of the keyframes nearest to that pose; the exported mesh is the
/// union of all patches, where a patch keeps only the triangles that earlier patches do not
/// already explain.
///
/// Eviction rule: when a new keyframe would exceed max_keyframes or the memory budget, the keyframe
/// with the smallest view distance to its nearest other keyframe (the most redundant view) goes;
/// among equals, the oldest. The newest keyframe is never evicted.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/mesh.h"
#include "scenewatch/core/result.h"

namespace scenewatch::background {

struct AppearanceConfig {
  bool enabled = true;
  /// A view is new when, to every keyframe, the camera moved this far or turned this much.
  /// Denser keyframes give better colour samples (the seed used every image of its first circle).
  double keyframe_min_translation_m = 0.05;
  double keyframe_min_rotation_deg = 5.0;
  std::size_t max_keyframes = 150;
  std::size_t memory_budget_mb = 512;   ///< images plus mesh patches
  int mesh_stride_px = 4;               ///< grid step of the triangulation, per 640 pixels of width
  /// An edge is cut where neighbouring depths differ by more than this fraction of the depth.
  double mesh_max_depth_jump = 0.05;
  int depth_views = 3;                  ///< patches of this many nearest keyframes render the expected depth
};

/// Validates ranges; the message names the key (e.g. "appearance.mesh_stride_px").
Status validate(const AppearanceConfig& config);

/// One reference view.
struct Keyframe {
  std::uint64_t id = 0;
  double stamp_s = 0.0;
  Pose T_world_camera = Pose::Identity();
  Intrinsics intrinsics;
  ColorImage color;
  DepthImage depth;
  std::size_t bytes() const { return color.rgb.size() + 2 * depth.depth_mm.size(); }
};

/// Builds a keyframe from an organized frame with intrinsics (depth = z of each point, colour =
/// its rgb). Error when the frame is not organized, has no intrinsics or they disagree in size.
Result<Keyframe> keyframe_from_frame(const Frame& frame);

/// Difference of two camera poses: translation and the angle between their rotations.
struct ViewDistance {
  double translation_m = 0, rotation_deg = 0;
};
ViewDistance view_distance(const Pose& a, const Pose& b);

/// Depth in metres per pixel, row-major; 0 where nothing was rendered.
struct DepthMap {
  int width = 0, height = 0;
  std::vector<float> depth_m;
};

/// NOT thread safe: the owner serialises writers against readers.
class AppearanceMemory {
 public:
  explicit AppearanceMemory(AppearanceConfig config = {});
  ~AppearanceMemory();
  AppearanceMemory(AppearanceMemory&&) noexcept;
  AppearanceMemory& operator=(AppearanceMemory&&) noexcept;

  /// True when the pose is far enough from every keyframe (always true when there is none).
  bool is_new_view(const Pose& T_world_camera) const;
  /// Adds a keyframe (its id is assigned here), triangulates its patch and evicts by the rule
  /// above. Error (and nothing changes) when images and intrinsics disagree in size.
  Result<std::uint64_t> add(Keyframe keyframe);
  /// Adds the keyframe when its view is new; returns whether it was added.
  Result<bool> consider(Keyframe keyframe);
  /// Replaces the keyframe nearest to this one's view (the scene there changed and the change is
  /// to be remembered); adds it when the memory is empty.
  Result<std::uint64_t> replace_nearest(Keyframe keyframe);

  /// Up to n keyframes that see towards the given view, nearest first (by translation plus
  /// rotation, each in units of its keyframe threshold). Keyframes looking away (optical axes
  /// more than 90 degrees apart) are not returned.
  std::vector<std::shared_ptr<const Keyframe>> nearest(const Pose& T_world_camera, std::size_t n) const;

  /// Expected depth at a pose: the z-buffer of the patches of the `depth_views` nearest keyframes.
  DepthMap render_depth(const Pose& T_world_camera, const Intrinsics& intrinsics) const;
  /// The same, from the patches of the given keyframes.
  DepthMap render_depth(const Pose& T_world_camera, const Intrinsics& intrinsics,
                        const std::vector<std::shared_ptr<const Keyframe>>& from) const;

  /// The background's textured mesh: the union of patches, each without the triangles that
  /// earlier patches already explain.
  ColoredMesh mesh() const;

  std::vector<std::shared_ptr<const Keyframe>> keyframes() const;
  std::size_t size() const;
  std::size_t memory_bytes() const;
  std::size_t triangle_count() const;
  void clear();

  /// Writes keyframes as keyframe-NNNNNN.{color,depth}.png + .pose.txt + .intrinsics.txt into dir.
  Status save(const std::filesystem::path& dir) const;
  /// Replaces the memory by the keyframes in dir (a missing dir: empty memory).
  Status load(const std::filesystem::path& dir);

  const AppearanceConfig& config() const { return config_; }

 private:
  struct Impl;
  AppearanceConfig config_;
  std::unique_ptr<Impl> impl_;
};

/// Renders a mesh's depth at a pose (z-buffer, nearest surface; 0 = none). Exposed for tests
/// and the mesh export check.
DepthMap render_mesh_depth(const ColoredMesh& mesh, const Pose& T_world_camera, const Intrinsics& intrinsics);

}  // namespace scenewatch::background
