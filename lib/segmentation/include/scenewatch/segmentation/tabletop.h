#pragma once
/// Tabletop segmentation: supporting planes by RANSAC, each with its convex hull, and the object
/// clusters standing on them (points in the prism above the hull, Euclidean clustering, then
/// split at concave creases so that touching and stacked objects come apart).
#include <optional>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::segmentation {

struct Config {
  double voxel_size_m = 0.01;          ///< working resolution for RANSAC and clustering
  int max_planes = 3;
  double plane_distance_m = 0.015;     ///< RANSAC inlier threshold
  int ransac_iterations = 200;
  std::uint32_t seed = 42;             ///< RANSAC seed: same seed, same planes
  /// Smaller planes are not supporting planes. Box faces in mOSD reach 0.06 m^2; the smallest
  /// support in the test data (PCL's stereo mug scene) is 0.19 m^2.
  double min_plane_area_m2 = 0.1;
  double plane_connectivity_m = 0.05;  ///< gaps narrower than this do not split a plane
  /// Optional up-vector in the cloud's frame: only planes whose normal is within
  /// max_normal_angle_deg of it are supporting planes.
  std::optional<Eigen::Vector3d> up;
  double max_normal_angle_deg = 15.0;
  double min_object_height_m = 0.01;   ///< points closer to the plane belong to it
  /// Far from the sensor, depth noise lifts plane points above min_object_height_m: a point must
  /// also rise this many standard deviations of the Kinect noise at its range above the plane
  /// (sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m, Nguyen, Izadi & Lovell 2012). 0 disables.
  double height_noise_sigmas = 3.0;
  double max_object_height_m = 0.5;
  double cluster_tolerance_m = 0.02;
  int min_cluster_points = 100;        ///< in input points
  int max_cluster_points = 500000;
  /// Touching and stacked objects are one Euclidean cluster; split each cluster at its concave
  /// creases (local convexity over patches, Stein et al. CVPR 2014). Organized clouds only (one
  /// view, whose sensor orients the normals), and unorganized clouds of one view through their
  /// recovered image (recover_image_grid); clouds merged from several views keep their Euclidean
  /// clusters.
  bool split_concave = true;
  double patch_size_m = 0.02;            ///< patch (voxel) edge for the convexity test
  /// Neighbouring patches whose normals differ by less than this are one smooth surface even
  /// when the connection looks concave. About twice the noise of the angle between two patch
  /// normals at 1.5 m: a 2 cm patch of a Kinect at 1.5 m (sigma_z 6 mm, ~50 points) has a normal
  /// error of ~8 degrees by the plane-fit formula sigma_z sqrt(12) / (L sqrt(N)).
  double concavity_tolerance_deg = 20.0;
  /// Concave links flatter than this are one object's curvature (the inside of a cup); steeper
  /// ones are creases between objects, which meet at about right angles: half of that.
  double crease_angle_deg = 45.0;
  /// An object behind a narrower one shows on both sides of it: join two pieces when the image
  /// between them is covered by something nearer and the surface continues across (organized
  /// clouds only).
  bool join_occluded = true;
  /// An unorganized cloud of one view (NaNs dropped, points reordered, a converter's output) is
  /// segmented through the image it was taken as (core/image_grid.h), so the cuts and joins above
  /// that need an image apply to it too. A cloud merged from several views keeps the voxel path.
  bool recover_image_grid = true;
  /// A pile cuts the visible table into pieces; bridge them through the cells the objects standing
  /// on it hide from the sensor, so everything on the table is on one support (one view only),
  /// and what stands on those hidden cells rests on it (its feet widen the hull).
  /// On mOSD's piles it finds 35 of 44 objects instead of 22 (tuning scenes) and 21 of 32 instead
  /// of 15 (held out). Only the first support and planes parallel to it are bridged, and only
  /// their hulls widen; pieces smaller than a cell do not join, and voxels within the sensor's
  /// noise of the plane hide nothing. A floor that is the largest plane is bridged too: YCB's
  /// frames list chairs on the floor (docs/clutter.md).
  bool bridge_hidden_support = true;
  /// Organized views (and unorganized ones through their recovered image): cut a convex part whose
  /// faces parallel to the support lie at levels farther apart than the sensor's noise (3 sigma of
  /// two depths): objects stacked flat, a book on a book, a box on a book. Each level is an
  /// object's top; the part's other points go first to the level whose band of heights they lie
  /// in, then to the nearest (segmentation/src/terrace_split.h, docs/clutter.md).
  bool split_stacked = true;
  /// The depth camera (the pipeline's `sensor` section): its noise at each range and incidence
  /// decides what is a depth step (split_depth_steps) and a level apart (split_stacked).
  SensorModel sensor;
  /// Organized clouds (and unorganized ones through their recovered image): cut the convex parts
  /// at closed depth steps, a box leaning on a can, a book lying on a book, a thin box on a box
  /// (1-3 cm). A step is a jump between two pixels whose sides' surfaces, carried to the boundary,
  /// miss each other by more than 3 sigma of the sensor's noise there; beside a hole, only when
  /// both sides also lie on their lines within that noise (segmentation/src/depth_steps.h).
  bool split_depth_steps = true;
  /// ... and at closed colour edges that run across a part (two boxes of different print pressed
  /// together): OpenCV's Canny on the colour image, its thresholds at 3 sigma of the image's own
  /// noise (segmentation/src/colour_edges.h).
  bool split_colour_edges = false;
};

/// Validates ranges; the message names the key (e.g. "segmentation.voxel_size_m").
Status validate(const Config& config);

struct Segmentation {
  std::vector<Plane> planes;          ///< in the order found: most voxel inliers first
  std::vector<ObjectCluster> objects; ///< most points first
};

/// Segments one cloud (organized or not). The sensor is at sensor_origin in the cloud's frame;
/// plane normals point towards it. Reproducible for a given config.seed. Thread safe (no state).
Segmentation segment(const Cloud& cloud, const Config& config,
                     const Eigen::Vector3d& sensor_origin = Eigen::Vector3d::Zero());

/// segment() on every `stride`-th pixel of every `stride`-th row of an organized cloud (a sample
/// stands for stride^2 pixels: min/max_cluster_points are divided by that), then back to every
/// pixel: a pixel belongs to the object of the nearest of the (up to) four samples around it when
/// that sample lies within one voxel_size_m of it, and to a plane when its sample is on the plane
/// and it lies within plane_distance_m of it. Indices and counts are the full cloud's; hulls,
/// boxes, centroids and colours are the samples'. About stride^2 times less work; at stride 2
/// a VGA Kinect's samples stay closer than the 1 cm voxel up to about 2.6 m on a surface facing
/// the camera, so far grazing surfaces (a room's walls) may come apart. Unorganized clouds and
/// stride 1: segment() itself, of the whole cloud. `max_range_m` > 0 (with a stride of 2 or more):
/// only the samples within that range of the sensor are segmented; the others belong to no plane
/// and no object.
Segmentation segment_strided(const Cloud& cloud, const Config& config, const Eigen::Vector3d& sensor_origin, int stride,
                             double max_range_m = 0);

}  // namespace scenewatch::segmentation
