#pragma once
/// Primitive fitting of one object: normals on its points, CGAL's Efficient RANSAC shape
/// detection over plane, cylinder, sphere and cone (Schnabel, Wahl & Klein 2007), then a
/// least-squares refinement of the largest cylinder (or nearly straight cone) that copes with a
/// single partial view.
#include <optional>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/result.h"
#include "scenewatch/ontology/primitive.h"

namespace scenewatch::ontology {

/// How the axis of a cylinder may be constrained.
enum class AxisPrior {
  kNone,     ///< the axis is fitted freely
  kUpright,  ///< when `up` is given and the detected axis is within upright_tolerance_deg of it,
             ///< the axis is held along `up` (objects standing on their support); without any
             ///< detected cylinder, an upright one is started from a circle fit of the side points
};

/// How the k nearest neighbours of the normal estimation are found.
enum class NormalSearch {
  kGrid,    ///< a hash grid sized to the points' typical k-th neighbour distance (as fast as the
            ///< kd-tree on an idle machine, about 1.5x faster while the cores are shared)
  kKdTree,  ///< PCL's NormalEstimation over a kd-tree: the former estimate, the benchmark's baseline
};

struct FitConfig {
  int normal_neighbours = 24;        ///< k nearest neighbours of the normal estimation
  NormalSearch normal_search = NormalSearch::kGrid;
  /// Objects with more valid points are subsampled to this many, evenly spaced, for the normals,
  /// the shape detection and the refinement (fit time stays bounded; 3000 keep the known cans'
  /// radii within 0.5 mm of those from 6000, at about half the time: docs/ontology.md, "Primitive fitting").
  int max_points = 3000;
  int min_points = 50;               ///< fewer valid points: an error, nothing to fit
  // Efficient RANSAC (CGAL::Shape_detection::Efficient_RANSAC::Parameters).
  double epsilon_m = 0.004;          ///< max point-to-shape distance of an inlier
  double cluster_epsilon_m = 0.012;  ///< max gap between connected inliers of one shape
  double normal_threshold = 0.85;    ///< min |cos| between point normal and shape normal
  double min_shape_fraction = 0.1;   ///< a shape explains at least this fraction of the points
  double probability = 0.05;         ///< probability to miss the largest shape
  unsigned seed = 42;                ///< same seed, same shapes
  bool detect_plane = true, detect_cylinder = true, detect_sphere = true, detect_cone = true;
  // Cylinder refinement.
  /// A detected cone with a half angle up to this is refined as a cylinder (CGAL explains some
  /// straight cups as cones of about 1 degree).
  double cylinder_max_cone_deg = 3.0;
  AxisPrior axis_prior = AxisPrior::kUpright;
  double upright_tolerance_deg = 25.0;
  double refine_band_m = 0.01;       ///< points within this radial distance of the cylinder are refitted
  /// and their normal (oriented to the sensor) within acos(this) of the outward radial direction
  double refine_min_normal_cos = 0.6;
  int refine_rounds = 3;             ///< re-select the band around the refined cylinder this often
  double huber_m = 0.003;            ///< Huber threshold of the robust least squares
  /// Points of an organized cloud (camera images) within this angle, seen from the sensor, of a
  /// depth discontinuity do not pull the refinement nor count as a vessel's inside wall (0: off):
  /// a structured-light sensor's correlation window straddles the edge there and biases their
  /// depth towards the surface's interior, flattening the seen arc (docs/ontology.md, "Primitive fitting").
  /// An angle, as the window is a few of the sensor's own pixels whatever the image's resolution:
  /// 0.2 degrees are 4 pixels of YCB-Video's 1067 px focal length, 2 of a 525 px VGA camera's.
  double edge_margin_deg = 0.2;
  /// Neighbouring pixels whose depths differ by more than this (or an invalid pixel) are a depth
  /// discontinuity; the segmentation's cluster_tolerance_m, the gap that separates two surfaces.
  double edge_jump_m = 0.02;
};

/// Validates ranges; the message names the key (e.g. "ontology.epsilon_m").
Status validate(const FitConfig& config);

/// Everything fitted to one object.
struct ObjectFit {
  std::vector<Primitive> shapes;        ///< shape detection's, most points first
  std::optional<CylinderFit> cylinder;  ///< the refined cylinder, when there is one
  int best = -1;                        ///< index in shapes of the best primitive (most points); -1: none
  std::size_t points = 0;               ///< valid points of the object
  std::size_t points_detected = 0;      ///< points given to the shape detection (after subsampling)
  /// Those points and their unit normals (oriented to the sensor), in the cloud's frame.
  std::vector<Eigen::Vector3d> sample_points, sample_normals;
  /// Per sample point: 1 when it lies within config.edge_margin_deg of a depth discontinuity (its
  /// depth, hence its normal, biased by the sensor); all 0 for an unorganized cloud.
  std::vector<char> sample_near_edge;
  double normals_ms = 0, detection_ms = 0, refinement_ms = 0;
};

/// Fits primitives to cloud[indices] (camera or world frame). `up`, when given, is the normal of
/// the supporting plane (the upright axis prior); the sensor at `sensor_origin` orients normals.
/// Errors: indices out of range, fewer than config.min_points valid points, an invalid config.
/// Reproducible for a given config.seed. Thread safe: CGAL's shape detection draws from CGAL's
/// default random generator, which is thread-local and which fit_object reseeds on each call.
Result<ObjectFit> fit_object(const Cloud& cloud, const std::vector<int>& indices, const FitConfig& config = {},
                             const std::optional<Eigen::Vector3d>& up = std::nullopt,
                             const Eigen::Vector3d& sensor_origin = Eigen::Vector3d::Zero());

}  // namespace scenewatch::ontology
