#pragma once
/// Per-pixel geometric mismatch between a model and a new observation at a known pose (issue 5).
///
/// "Added": an observed point lies where the model knows space to be free, farther than a
/// depth-dependent tolerance from any surface of the model. "Removed": a model surface lies in
/// front of the observed depth at its pixel by more than the tolerance, so this frame's ray passed
/// through it. Unknown space, occluded surfaces and pixels without depth claim nothing.
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/change/pose_agreement.h"
#include "scenewatch/change/surface_witness.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::change {

class DarkSpace;

struct Config {
  /// The depth camera and the pose source every piece of evidence is measured against (in the
  /// working memory: its `sensor:` section, copied in by WorkingMemory).
  SensorModel sensor;
  /// Tolerance at depth z: max(min_tolerance_m, sigma_factor * sigma), sigma the sensor's axial
  /// noise at z (structured light: 0.0012 + 0.0019 (z - 0.4)^2 m, Nguyen, Izadi & Lovell 2012)
  /// combined, against a map, with the pose's uncertainty at that range.
  double sigma_factor = 3.0;
  double min_tolerance_m = 0.01;
  /// Against a map: only pixels with a depth in the sensor's working range and off its image
  /// border (sensor.border_px) are evidence. false: every pixel with depth.
  bool trusted_pixels_only = true;
  /// Against a map: the pose's uncertainty in each frame is measured (pose_agreement.h), and the
  /// larger of it and the declared one (sensor.pose_sigma_m, pose_sigma_deg) counts. false: the
  /// declared one alone.
  bool measure_pose = true;
  /// Against a map that several cameras feed (WorkingMemory): a camera claims change only against
  /// surfaces it saw itself (SurfaceWitness, surface_witness.h). false: against every surface of
  /// the map, whoever saw it.
  bool witness_per_camera = true;
  /// Against a map: a point in free space claims a new surface only when it lies farther from
  /// every surface than its noise along the ray at the incidence its surface is seen at
  /// (SensorModel::sigma_along_ray, core/surface_incidence.h) allows. A surface seen at a grazing
  /// angle (a cupboard's side, a standing magazine) is placed only coarsely along the ray, and the
  /// space in front of it was carved by rays running along it. false: the head-on noise alone.
  bool incidence_aware = true;
  /// Against a map with a DarkSpace (dark_space.h): space the sensor got no return from, in front
  /// of a known surface, from persistence_frames frames and two directions (a clear glass), is
  /// removed when a frame sees through it. false: only the map's surfaces can be removed.
  bool see_through_dark = true;
  /// Only voxels the map holds occupied with at least this probability can be claimed removed:
  /// a surface seen once (a flying pixel at a silhouette) is no evidence of an object. A map
  /// built from one frame holds prob_hit (0.7); diff() lowers the threshold to it.
  double min_surface_probability = 0.8;
  /// Only depths up to this claim anything (Kinect noise beyond is as large as a voxel, and the
  /// dense grid grows with the cube of the range).
  double max_range_m = 2.5;
  /// Mismatch points are grouped over a voxel grid of this edge (26-connected cells).
  double cluster_voxel_m = 0.02;
  /// A cluster whose largest box side is below this is noise (border residue, speckle).
  double min_object_size_m = 0.025;
  std::size_t min_cluster_points = 15;  ///< and so is one with fewer points (or voxels, for removed)
  /// ... and one whose evidence covers less surface than this (pixels weighted by their metric
  /// footprint (z/f)^2, voxels by their face): a 3 cm object shows at least about 2 x 2 cm.
  double min_object_area_m2 = 0.0004;
  /// Same-camera pairs: a changed pixel counts only when this many of its 8 neighbours changed
  /// too (removes one-pixel slivers along depth edges).
  int min_changed_neighbours = 5;
  /// Pairing a vanished cluster with an appeared one as a move: sorted box sides within this
  /// ratio, mean colours within this RGB distance, and a centroid displacement of at least
  /// min_move_m (below it the two are one object's border residue).
  double move_max_size_ratio = 2.0;
  double move_max_color_distance = 80.0;
  double move_min_distance_m = 0.03;
  /// Whole-object completion of diffs (whole_objects.h): each side of a change is replaced by the
  /// segmented objects of its frame that its evidence substantially belongs to. An object joins
  /// when it carries at least `completion_evidence_share` of the evidence (the evidence is mostly
  /// its surface: the fringe a short move uncovers, whatever the share of the object) or when the
  /// evidence covers at least `completion_object_share` of its points (most of it changed, though
  /// the evidence spreads over neighbours too). Both are majorities: a minority of stray evidence
  /// (a shadow edge, a neighbour's border) never pulls in a whole object.
  bool complete_objects = true;
  double completion_evidence_share = 0.5;
  double completion_object_share = 0.5;
  /// The segmentation for completion runs on every n-th pixel of every n-th row of organized
  /// clouds. At tabletop range a Kinect pixel spans 1-2 mm and the segmentation's voxel 10 mm, so
  /// every second pixel still leaves several samples across each voxel, at a quarter of the points.
  int completion_stride_px = 2;
  /// Sequences: a change fires after this many consistent frames (1 = at once).
  int persistence_frames = 3;
  /// A candidate is re-observed when a cluster of its kind lies within this distance.
  double persistence_match_m = 0.06;
  /// Largest dense grid built from the map for one frame (voxels).
  std::size_t max_grid_voxels = std::size_t{1} << 25;
};

/// Validates ranges; the message names the key ("change.persistence_frames: ...").
Status validate(const Config& config);

/// The tolerance at depth z (metres): the sensor's noise alone (same-camera pairs).
double tolerance_m(const Config& config, double z);
/// The tolerance at depth z against a map (metres): sigma_factor times the sensor's noise and the
/// declared pose uncertainty (sensor.pose_sigma_*) together, plus how far the frame's measured
/// misalignment (pose_agreement.h) has moved the point: a measured offset, not a spread.
double map_tolerance_m(const Config& config, double z, double pose_shift_m = 0.0);
/// ... for a measurement whose own noise is sensor_sigma_m (SensorModel::sigma_along_ray).
double map_tolerance_from_sigma(const Config& config, double sensor_sigma_m, double z, double pose_shift_m = 0.0);

/// A depth image in some camera: z per pixel (NaN where none), plus that camera.
struct DepthView {
  Intrinsics K;
  std::vector<float> z;  ///< row-major, K.width * K.height
  /// The smallest and largest depth in `z` (both NaN when it holds none): depth_view() finds them
  /// as it fills `z`; a view filled by hand sets them too.
  float min_z = std::numeric_limits<float>::quiet_NaN(), max_z = std::numeric_limits<float>::quiet_NaN();
  float at(int u, int v) const { return z[static_cast<std::size_t>(v) * K.width + u]; }
};

/// The camera an observation is seen with: the given intrinsics, else those fitted to an
/// organized cloud (io::estimate_intrinsics), else a virtual pinhole covering the points of an unorganized cloud.
Result<Intrinsics> observation_camera(const Cloud& points_camera, const std::optional<Intrinsics>& K);

/// The depth image of a cloud seen from its own camera (an organized cloud: its z; otherwise a
/// z-buffer of the projected points, nearest wins).
DepthView depth_view(const Cloud& points_camera, const Intrinsics& K);

/// A model voxel this observation saw through.
struct MissingVoxel {
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();
  std::uint32_t rgb = 0;  ///< the model's colour there, 0xRRGGBB
  int u = 0, v = 0;       ///< pixel of its centre
  float depth_gap_m = 0;  ///< observed depth minus the voxel's
  /// Dark space (dark_space.h), not a surface of the map: volume, without colour.
  bool dark = false;
};

/// Raw mismatch of one observation.
struct Mismatch {
  std::vector<int> added;             ///< indices of observed points in space the model holds free
  std::vector<float> added_gap_m;     ///< per added point: distance to the nearest model surface (capped)
  std::vector<MissingVoxel> missing;  ///< model voxels the rays passed through
  double voxel_m = 0.0;               ///< the map's voxel edge (map path)
  PoseAgreement pose;                 ///< map path: how well the frame's pose agrees with the map
  std::size_t trusted_pixels = 0;     ///< map path: pixels the sensor model trusts
  /// Map path: the observation's depth image as the comparison read it (DarkSpace::record reads
  /// it again rather than building it a second time).
  std::shared_ptr<const DepthView> depth;
  /// Removed side given as points of an earlier organized observation (same-camera pairs); its
  /// indices index that observation. Empty for the map path.
  std::vector<int> removed_points;
  double grid_ms = 0, added_ms = 0, missing_ms = 0;  ///< where the time went
};

/// Compares an observation (points in the camera frame, placed with T_world_camera) with the
/// map. Error when the region is too large for a dense grid or the camera is invalid. A caller
/// that compares every frame passes `grid_scratch`, the dense copy of the map, kept between calls
/// so that its buffers are allocated once. With `witness`, the observation's camera (`camera`)
/// claims nothing against a surface only other cameras have seen: a point in free space whose ray
/// meets such a surface behind it, a voxel only they saw (surface_witness.h).
///
/// With `dark` (and config.see_through_dark), the dark voxels (dark_space.h) the frame sees
/// through are removed voxels too, of colour 0; every recorded voxel the frame sees through is
/// marked so in `dark`.
///
/// `grid_filled`: `grid_scratch` already holds the map around comparison_box() of this
/// observation or a larger box (filled ahead, beside other work), and that box was found (some
/// point is within range); the grid is used as it is.
Result<Mismatch> mismatch_against_map(const background::OccupancyMap& map, const Cloud& points_camera,
                                      const Pose& T_world_camera, const Intrinsics& K, const Config& config,
                                      background::DenseGrid* grid_scratch = nullptr, const SurfaceWitness* witness = nullptr,
                                      std::uint32_t camera = 0, bool grid_filled = false, DarkSpace* dark = nullptr);

/// The box of the map mismatch_against_map() compares an observation with: its points within
/// max_range_m, placed in the world, widened by two voxels of `resolution_m`. Nullopt when no
/// point is within range.
std::optional<Aabb> comparison_box(const Cloud& points_camera, const Pose& T_world_camera, const Config& config,
                                   double resolution_m);

/// Whether comparison_box() would find a box: some point is valid and within max_range_m.
bool any_point_in_range(const Cloud& points_camera, const Config& config);

/// Same-camera pair of organized clouds of equal size (the camera did not move): exact per-pixel
/// reasoning. A pixel whose AFTER depth is in front of BEFORE by more than the tolerance is added
/// (BEFORE saw through that space); BEFORE in front of AFTER is removed (AFTER saw through it).
/// Error when the sizes differ or the clouds are not organized.
Result<Mismatch> mismatch_same_camera(const Cloud& before_camera, const Cloud& after_camera, const Config& config);

}  // namespace scenewatch::change
