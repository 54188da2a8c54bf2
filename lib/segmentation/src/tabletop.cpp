// Tabletop segmentation on a voxel grid:
//  1. voxelize the valid points (centroid per voxel, point -> voxel map);
//  2. RANSAC planes on the voxel centroids (seeded, optional up-vector constraint), refined by
//     least squares; each plane keeps its largest connected part (a 2D grid on the plane bridges
//     the shadows that objects cast on the table and, seen from one view, the table hidden
//     behind a pile: support_extent.h);
//  3. convex hull of each plane (Andrew's monotone chain in the plane's 2D basis), widened by
//     the feet of what stands where the table is hidden (support_extent.h);
//  4. voxels in the prism above a hull are clustered (Euclidean, union-find over grid
//     neighbours), and every input point of a cluster voxel at object height joins the object.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <limits>
#include <random>

#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/core/plane_fit.h"
#include "boundary_cut.h"
#include "terrace_split.h"
#include "colour_edges.h"
#include "containers.h"
#include "convex_parts.h"
#include "depth_steps.h"
#include "hull2d.h"
#include "occlusion_join.h"
#include "support.h"
#include "support_extent.h"
#include "through_image.h"
#include "union_find.h"
#include "voxel_columns.h"
#include "voxel_index.h"

namespace scenewatch::segmentation {
namespace {


struct PlaneModel {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  double distance(const Eigen::Vector3f& p) const { return n.dot(p.cast<double>()) + d; }
};

// Least-squares plane through points (plane_fit.h), its normal normalized.
PlaneModel fit_plane(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& ids) {
  const PlaneFit fit = fit_plane_least_squares(centroids, ids);
  PlaneModel m;
  m.n = fit.normal.normalized();
  m.d = -m.n.dot(fit.mean);
  return m;
}

struct RansacResult {
  bool found = false;
  PlaneModel model;
};

// RANSAC over the candidate voxels. Hypotheses are scored on a fixed random subset for speed;
// the caller recomputes the inliers on all candidates. Adaptive termination (Fischler & Bolles;
// Hartley & Zisserman, Multiple View Geometry, sec. 4.7.1): stop once N = log(1 - p) / log(1 - w^3)
// hypotheses have been drawn for the best inlier ratio w so far, with p = 0.999;
// config.ransac_iterations is the upper bound.
RansacResult ransac_plane(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& candidates,
                          const Config& cfg, const std::optional<Eigen::Vector3d>& up, std::mt19937& rng) {
  RansacResult best;
  if (candidates.size() < 3) return best;
  constexpr std::size_t kScoreSamples = 3000;
  constexpr double kConfidence = 0.999;
  constexpr int kMinIterations = 20;
  std::vector<Eigen::Vector3f> scoring;
  scoring.reserve(std::min(kScoreSamples, candidates.size()));
  if (candidates.size() > kScoreSamples) {
    std::vector<int> pick = candidates;
    std::shuffle(pick.begin(), pick.end(), rng);
    for (std::size_t i = 0; i < kScoreSamples; ++i) scoring.push_back(centroids[pick[i]]);
  } else {
    for (int v : candidates) scoring.push_back(centroids[v]);
  }
  const double cos_max = std::cos(cfg.max_normal_angle_deg * M_PI / 180.0);
  const float threshold = static_cast<float>(cfg.plane_distance_m);
  std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
  std::size_t best_score = 0;
  double needed = cfg.ransac_iterations;
  for (int it = 0; it < cfg.ransac_iterations && it < needed; ++it) {
    const Eigen::Vector3d a = centroids[candidates[pick(rng)]].cast<double>();
    const Eigen::Vector3d b = centroids[candidates[pick(rng)]].cast<double>();
    const Eigen::Vector3d c = centroids[candidates[pick(rng)]].cast<double>();
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    if (len < 1e-9) continue;  // collinear or repeated sample
    n /= len;
    if (up && std::abs(n.dot(*up)) < cos_max) continue;
    const Eigen::Vector3f nf = n.cast<float>();
    const float d = static_cast<float>(-n.dot(a));
    std::size_t score = 0;
    for (const auto& q : scoring) score += std::abs(nf.dot(q) + d) < threshold ? 1 : 0;
    if (score > best_score) {
      best_score = score;
      best.found = true;
      best.model = {n, static_cast<double>(d)};
      const double w = static_cast<double>(score) / scoring.size();
      const double miss = 1.0 - w * w * w;
      needed = miss <= 0.0 ? 0.0 : std::max<double>(kMinIterations, std::log(1.0 - kConfidence) / std::log(miss));
    }
  }
  return best;
}

// Least height above the plane at which a point at `range_m` from the sensor counts as an object:
// min_object_height_m, or the sensor's depth noise there (Nguyen, Izadi & Lovell, "Modeling Kinect
// Sensor Noise for Improved 3D Reconstruction and Tracking", 3DIMPVT 2012: axial noise
// sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 m), whichever is larger.
double object_height_threshold(const Config& cfg, double range_m) {
  const double dz = std::max(0.0, range_m - 0.4);
  return std::max(cfg.min_object_height_m, cfg.height_noise_sigmas * (0.0012 + 0.0019 * dz * dz));
}

struct PlaneFrame {
  PlaneModel model;
  Eigen::Vector3d u, v;
  std::vector<Vec2> hull2d;
  std::vector<Vec2> own_hull2d;  ///< the hull before the feet below widen it
  Vec2 at(const Eigen::Vector3d& q) const { return Vec2(q.dot(u), q.dot(v)); }
  Eigen::Vector3d origin_on_plane() const { return -model.d * model.n; }
  /// hull2d back in 3D, on the plane.
  std::vector<Eigen::Vector3d> hull_3d() const {
    std::vector<Eigen::Vector3d> out;
    out.reserve(hull2d.size());
    for (const Vec2& h : hull2d) out.push_back(origin_on_plane() + h.x() * u + h.y() * v);
    return out;
  }
};

// Box with its z axis along the plane normal and the yaw of the minimum-area rectangle around
// the points' footprint (rotating calipers over the 2D hull; PCA is ambiguous for square shapes).
OrientedBox box_on_plane(const Cloud& cloud, const std::vector<int>& idx, const Eigen::Vector3d& n) {
  Eigen::Vector3d u, v;
  plane_basis(n, u, v);
  std::vector<Vec2> footprint;
  footprint.reserve(idx.size());
  for (int i : idx) {
    const Eigen::Vector3d p = cloud[i].getVector3fMap().cast<double>();
    footprint.emplace_back(p.dot(u), p.dot(v));
  }
  const std::vector<Vec2> hull = convex_hull(std::move(footprint));
  Vec2 best_dir(1, 0);
  double best_area = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < hull.size() && hull.size() >= 2; ++i) {
    const Vec2 e = hull[(i + 1) % hull.size()] - hull[i];
    if (e.norm() < 1e-9) continue;
    const Vec2 dx = e.normalized(), dy(-dx.y(), dx.x());
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const Vec2& h : hull) {
      x0 = std::min(x0, h.dot(dx));
      x1 = std::max(x1, h.dot(dx));
      y0 = std::min(y0, h.dot(dy));
      y1 = std::max(y1, h.dot(dy));
    }
    const double area = (x1 - x0) * (y1 - y0);
    if (area < best_area) {
      best_area = area;
      // The box's x axis is its longer side.
      best_dir = (x1 - x0) >= (y1 - y0) ? dx : dy;
    }
  }
  const Eigen::Vector3d ax = (best_dir.x() * u + best_dir.y() * v).normalized();
  const Eigen::Vector3d ay = n.cross(ax);
  Eigen::Matrix3d R;
  R << ax, ay, n;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (int i : idx) {
    const Eigen::Vector3d q = R.transpose() * cloud[i].getVector3fMap().cast<double>();
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  OrientedBox box;
  box.rotation = Eigen::Quaterniond(R);
  box.center = R * (0.5 * (lo + hi));
  box.extents = hi - lo;
  return box;
}

// Whether most voxels of a plane candidate lie in the prism of an earlier support, at object
// height: then they are an object's face.
bool on_objects_of(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& part,
                   const std::vector<PlaneFrame>& supports, const Config& cfg, const Eigen::Vector3d& sensor_origin) {
  std::size_t above = 0;
  for (int v : part) {
    const Eigen::Vector3d q = centroids[v].cast<double>();
    for (const PlaneFrame& f : supports) {
      const double h = f.model.distance(centroids[v]);
      if (h >= object_height_threshold(cfg, (q - sensor_origin).norm()) && h <= cfg.max_object_height_m &&
          inside_convex(f.hull2d, f.at(q))) {
        ++above;
        break;
      }
    }
  }
  return 2 * above > part.size();
}

ObjectCluster make_object(const Cloud& cloud, std::vector<int> indices, int plane_id, const Eigen::Vector3d& up) {
  ObjectCluster obj;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), rgb = Eigen::Vector3d::Zero();
  for (int i : indices) {
    sum += cloud[i].getVector3fMap().cast<double>();
    rgb += Eigen::Vector3d(cloud[i].r, cloud[i].g, cloud[i].b);
  }
  const double n = static_cast<double>(indices.size());
  obj.plane_id = plane_id;
  obj.point_count = indices.size();
  obj.centroid = sum / n;
  obj.mean_rgb = (rgb / n).cast<float>();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i : indices) {
    const Eigen::Vector3d d = Eigen::Vector3d(cloud[i].r, cloud[i].g, cloud[i].b) - rgb / n;
    covariance += d * d.transpose();
  }
  obj.rgb_covariance = (covariance / n).cast<float>();
  obj.box = box_on_plane(cloud, indices, up);
  obj.indices = std::move(indices);
  return obj;
}

ConvexityParams convexity_params(const Config& cfg) {
  ConvexityParams p;
  p.patch_size_m = cfg.patch_size_m;
  p.concavity_tolerance_deg = cfg.concavity_tolerance_deg;
  p.crease_angle_deg = cfg.crease_angle_deg;
  return p;
}

}  // namespace

Status validate(const Config& c) {
  auto bad = [](const std::string& key, const std::string& why) { return invalid_argument("segmentation." + key + ": " + why); };
  if (!(c.voxel_size_m >= 0.002 && c.voxel_size_m <= 0.2)) return bad("voxel_size_m", "must be in [0.002, 0.2] m, got " + std::to_string(c.voxel_size_m));
  if (c.max_planes < 0 || c.max_planes > 20) return bad("max_planes", "must be in [0, 20], got " + std::to_string(c.max_planes));
  if (!(c.plane_distance_m > 0 && c.plane_distance_m < 0.5)) return bad("plane_distance_m", "must be in (0, 0.5) m");
  if (c.ransac_iterations < 1 || c.ransac_iterations > 100000) return bad("ransac_iterations", "must be in [1, 100000]");
  if (!(c.min_plane_area_m2 >= 0)) return bad("min_plane_area_m2", "must be >= 0");
  if (!(c.plane_connectivity_m > 0)) return bad("plane_connectivity_m", "must be > 0");
  if (c.up && (!c.up->allFinite() || c.up->norm() < 1e-6)) return bad("up_vector", "must be a non-zero finite vector");
  if (!(c.max_normal_angle_deg > 0 && c.max_normal_angle_deg <= 90)) return bad("max_normal_angle_deg", "must be in (0, 90]");
  if (!(c.min_object_height_m >= 0 && c.min_object_height_m < c.max_object_height_m))
    return bad("min_object_height_m", "must be >= 0 and below max_object_height_m");
  if (!(c.height_noise_sigmas >= 0 && c.height_noise_sigmas <= 10)) return bad("height_noise_sigmas", "must be in [0, 10]");
  if (!(c.cluster_tolerance_m > 0 && c.cluster_tolerance_m <= 0.5)) return bad("cluster_tolerance_m", "must be in (0, 0.5] m");
  if (c.min_cluster_points < 1 || c.min_cluster_points > c.max_cluster_points)
    return bad("min_cluster_points", "must be >= 1 and <= max_cluster_points");
  if (!(c.patch_size_m >= 0.005 && c.patch_size_m <= 0.1)) return bad("patch_size_m", "must be in [0.005, 0.1] m");
  if (!(c.concavity_tolerance_deg >= 0 && c.concavity_tolerance_deg < 90)) return bad("concavity_tolerance_deg", "must be in [0, 90)");
  if (!(c.crease_angle_deg >= c.concavity_tolerance_deg && c.crease_angle_deg <= 180))
    return bad("crease_angle_deg", "must be in [concavity_tolerance_deg, 180]");
  if (auto st = validate(c.sensor); !st) return st;
  return {};
}

namespace {

// Least-squares refinement until the inlier set stops growing: a hypothesis a few degrees off
// catches only a band of a large table, and the band widens a little with each round (two fixed
// rounds left a 1.2 m table tilted by 2.4 degrees in a simulated scene).
std::vector<int> refine_plane(const std::vector<Eigen::Vector3f>& centroids, const std::vector<int>& candidates,
                              const Config& cfg, PlaneModel& model) {
  std::vector<int> inliers;
  for (int refine = 0; refine < 10; ++refine) {
    std::vector<int> next;
    for (int v : candidates) {
      if (std::abs(model.distance(centroids[v])) < cfg.plane_distance_m) next.push_back(v);
    }
    if (next.size() < 3 || (refine > 0 && next.size() <= inliers.size())) break;
    inliers.swap(next);
    model = fit_plane(centroids, inliers);
  }
  return inliers;
}

// The plane record of a support: its hull in 3D and its inlier points (the points of its voxels,
// marked `mark` in in_plane, close to it and below object height), in one pass in index order.
Plane make_plane(const Cloud& cloud, const VoxelIndex& grid, const std::vector<char>& in_plane, char mark,
                 const PlaneFrame& frame, double area, const Config& cfg, const Eigen::Vector3d& sensor_origin) {
  const PlaneModel& model = frame.model;
  Plane plane;
  plane.normal = model.n;
  plane.d = model.d;
  plane.area_m2 = area;
  plane.hull = frame.hull_3d();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int v = grid.point_voxel[i];
    if (v < 0 || in_plane[v] != mark) continue;
    const Eigen::Vector3f q = cloud[i].getVector3fMap();
    const double h = model.distance(q);
    if (std::abs(h) < cfg.plane_distance_m && h < object_height_threshold(cfg, (q.cast<double>() - sensor_origin).norm())) {
      plane.indices.push_back(static_cast<int>(i));
      sum += q.cast<double>();
    }
  }
  plane.inlier_count = plane.indices.size();
  plane.centroid = plane.inlier_count > 0 ? Eigen::Vector3d(sum / static_cast<double>(plane.inlier_count)) : frame.origin_on_plane();
  return plane;
}

// What stands where a support is hidden rests on it, and its feet widen the support's hull
// (support_extent.h), unless they are on another support, in its band and its hull (a writing
// tablet on a floor): that one holds them.
void widen_by_resting_feet(std::vector<PlaneFrame>& frames, std::vector<Plane>& planes,
                           const std::vector<std::vector<Eigen::Vector3d>>& feet, double band_m) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    PlaneFrame& f = frames[i];
    std::vector<Vec2> pts2 = f.own_hull2d;
    for (const Eigen::Vector3d& q : feet[i]) {
      bool elsewhere = false;
      for (std::size_t j = 0; j < frames.size() && !elsewhere; ++j)
        elsewhere = j != i && std::abs(frames[j].model.distance(q.cast<float>())) <= band_m &&
                    inside_convex(frames[j].own_hull2d, frames[j].at(q));
      if (!elsewhere) pts2.push_back(f.at(q));
    }
    if (pts2.size() == f.own_hull2d.size()) continue;
    f.hull2d = convex_hull(std::move(pts2));
    planes[i].hull = f.hull_3d();
    planes[i].area_m2 = polygon_area(f.hull2d);
  }
}

// Supporting planes, largest first: RANSAC on the voxel centroids, least-squares refinement,
// the largest connected part, its hull; object faces inside an earlier support's prism are
// skipped. Marks each plane's voxels in `in_plane` (plane id + 1) and appends to `planes`.
std::vector<PlaneFrame> find_supports(const Cloud& cloud, const VoxelIndex& grid, const Config& cfg,
                                      const Eigen::Vector3d& sensor_origin, std::vector<char>& in_plane,
                                      std::vector<Plane>& planes) {
  const auto& centroids = grid.centroids;
  const std::size_t nvox = centroids.size();
  std::optional<Eigen::Vector3d> up;
  if (cfg.up) up = cfg.up->normalized();
  std::mt19937 rng(cfg.seed);
  in_plane.assign(nvox, 0);
  std::vector<PlaneFrame> frames;
  std::vector<std::vector<Eigen::Vector3d>> feet_of;  // per frame: support_extent's hidden feet
  std::vector<int> remaining(nvox);
  std::iota(remaining.begin(), remaining.end(), 0);
  for (int p = 0; p < cfg.max_planes; ++p) {
    const RansacResult r = ransac_plane(centroids, remaining, cfg, up, rng);
    if (!r.found) break;
    PlaneModel model = r.model;
    const std::vector<int> inliers = refine_plane(centroids, remaining, cfg, model);
    if (inliers.size() < 3) break;
    // Normals point to where objects stand: along up when given, else towards the sensor.
    const Eigen::Vector3d towards = up ? *up : (sensor_origin - centroids[inliers[0]].cast<double>());
    if (model.n.dot(towards) < 0) {
      model.n = -model.n;
      model.d = -model.d;
    }
    if (up && model.n.dot(*up) < std::cos(cfg.max_normal_angle_deg * M_PI / 180.0)) break;

    PlaneFrame frame;
    frame.model = model;
    plane_basis(model.n, frame.u, frame.v);
    // One view sees where a pile hides the plane: its visible pieces around the pile are one
    // support (support_extent.h). A merged cloud has no single viewpoint. Only the first support
    // and those parallel to it (within max_normal_angle_deg: a table over a floor) are bridged:
    // the shadows of everything over a plane tilted against it (with a small min_plane_area_m2,
    // patches across a YCB frame) joined its patches into a 1.5 m2 support that took objects
    // from the table.
    std::optional<Eigen::Vector3d> viewpoint;
    const bool parallel_to_first =
        frames.empty() || std::abs(model.n.dot(frames.front().model.n)) >= std::cos(cfg.max_normal_angle_deg * M_PI / 180.0);
    if (cfg.bridge_hidden_support && cloud.height > 1 && parallel_to_first) viewpoint = sensor_origin;
    const double cell_voxels = cfg.plane_connectivity_m / cfg.voxel_size_m;
    const PlaneGrid plane_grid{model.n, frame.u, frame.v, model.d, cfg.plane_connectivity_m,
                               static_cast<std::size_t>(std::ceil(cell_voxels * cell_voxels))};
    std::vector<int> visible;
    std::vector<Eigen::Vector3d> feet;
    const std::vector<int> part =
        support_extent(centroids, inliers, plane_grid, remaining, viewpoint, cfg.plane_distance_m, cfg.max_object_height_m,
                       [&cfg](double range_m) { return object_height_threshold(cfg, range_m); }, &visible, &feet);
    const auto hull_of = [&](const std::vector<int>& voxels) {
      std::vector<Vec2> pts2;
      pts2.reserve(voxels.size());
      for (int v : voxels) pts2.push_back(frame.at(centroids[v].cast<double>()));
      return convex_hull(std::move(pts2));
    };
    // The largest remaining plane is too small: no further supporting plane can be found. Judged
    // on its largest visible piece: bridging extends a support and never makes one (a second plane's
    // 0.06 m2 joined a piece of 45 voxels 3.2 m from the sensor and grew to 0.24 m2 in a YCB frame).
    frame.hull2d = hull_of(visible);
    if (frame.hull2d.size() < 3 || polygon_area(frame.hull2d) < cfg.min_plane_area_m2) break;
    // A plane standing in the prism of a support found before is the face of an object on it
    // (the top of a large box), not a support: it stays with the objects. What stands on it
    // is found by support reasoning (support.h).
    if (on_objects_of(centroids, visible, frames, cfg, sensor_origin)) {
      std::vector<char> face(nvox, 0);
      for (int v : visible) face[v] = 1;
      remaining.erase(std::remove_if(remaining.begin(), remaining.end(), [&](int v) { return face[v] != 0; }), remaining.end());
      continue;
    }
    // The bridged pieces widen the support's hull and nothing else: its inliers, and so the
    // planes found after it, are those of its largest visible piece, as without bridging (a
    // floor that took in its other pieces left a YCB frame's writing tablet to a RANSAC draw
    // tilted by 7 degrees, and the tuna can on it was fitted off its axis).
    if (part.size() != visible.size()) frame.hull2d = hull_of(part);
    frame.own_hull2d = frame.hull2d;
    feet_of.push_back(std::move(feet));
    const double area = polygon_area(frame.hull2d);

    const char mark = static_cast<char>(1 + planes.size());
    for (int v : visible) in_plane[v] = mark;
    planes.push_back(make_plane(cloud, grid, in_plane, mark, frame, area, cfg, sensor_origin));
    planes.back().id = static_cast<int>(planes.size()) - 1;
    frames.push_back(std::move(frame));

    std::vector<int> next;
    next.reserve(remaining.size());
    for (int v : remaining) {
      if (!in_plane[v]) next.push_back(v);
    }
    remaining.swap(next);
  }
  widen_by_resting_feet(frames, planes, feet_of, cfg.plane_distance_m);
  return frames;
}

// Euclidean clusters of the points standing on the supports (in their prisms, at object height),
// each with the plane it stands on; clusters attached to a taller structure are left out.
std::vector<Piece> euclidean_clusters(const Cloud& cloud, const VoxelIndex& grid, const std::vector<PlaneFrame>& frames,
                                      const std::vector<char>& in_plane, const Config& cfg,
                                      const Eigen::Vector3d& sensor_origin) {
  const auto& centroids = grid.centroids;
  const std::size_t nvox = centroids.size();
  // Object voxels: in the prism above a hull; the lowest such plane owns the voxel.
  std::vector<int> owner(nvox, -1);
  std::vector<int> object_voxels;
  for (std::size_t v = 0; v < nvox; ++v) {
    double best_h = std::numeric_limits<double>::max();
    const double min_h = object_height_threshold(cfg, (centroids[v].cast<double>() - sensor_origin).norm());
    for (std::size_t p = 0; p < frames.size(); ++p) {
      const double h = frames[p].model.distance(centroids[v]);
      if (h < min_h || h > cfg.max_object_height_m || h >= best_h) continue;
      const Eigen::Vector3d q = centroids[v].cast<double>();
      if (!inside_convex(frames[p].hull2d, frames[p].at(q))) continue;
      best_h = h;
      owner[v] = static_cast<int>(p);
    }
    if (owner[v] >= 0) object_voxels.push_back(static_cast<int>(v));
  }

  // Euclidean clustering of object voxels (grid neighbours within the tolerance).
  std::vector<int> local(nvox, -1);
  for (std::size_t i = 0; i < object_voxels.size(); ++i) local[object_voxels[i]] = static_cast<int>(i);
  UnionFind uf(object_voxels.size());
  const int reach = static_cast<int>(std::ceil(cfg.cluster_tolerance_m / cfg.voxel_size_m));
  const float tol2 = static_cast<float>(cfg.cluster_tolerance_m * cfg.cluster_tolerance_m);
  // An object standing on a plane ends below max_object_height_m. A voxel that touches non-plane
  // voxels higher than that above its own plane belongs to a larger structure (the foot of a
  // wall, a cabinet) and takes its cluster out.
  std::vector<char> attached(object_voxels.size(), 0);
  const VoxelColumns columns(grid);
  // Each pair of neighbours once, in no set order: the partition and the flags do not depend on it.
  // Plane voxels that are no object voxels take no part.
  columns.for_each_pair(
      reach, [&](int v) { return local[v] >= 0 || !in_plane[v]; },
      [&](int a, int b) {
        if ((centroids[a] - centroids[b]).squaredNorm() > tol2) return;
        const int ia = local[a], ib = local[b];
        if (ia >= 0 && ib >= 0) {
          if (owner[a] == owner[b]) uf.unite(ia, ib);
        } else if (ia >= 0) {
          if (frames[owner[a]].model.distance(centroids[b]) > cfg.max_object_height_m) attached[ia] = 1;
        } else if (ib >= 0) {
          if (frames[owner[b]].model.distance(centroids[a]) > cfg.max_object_height_m) attached[ib] = 1;
        }
      });
  for (std::size_t i = 0; i < object_voxels.size(); ++i) {
    if (attached[i]) attached[uf.find(static_cast<int>(i))] = 1;
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of(object_voxels.size(), -1);
  for (std::size_t i = 0; i < object_voxels.size(); ++i) {
    const int root = uf.find(static_cast<int>(i));
    if (group_of[root] < 0) {
      group_of[root] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of[root]].push_back(object_voxels[i]);
  }

  // Points of each group, in one pass over the cloud in index order (lists come out sorted);
  // only points at object height above their plane count.
  std::vector<int> voxel_group(nvox, -1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (attached[uf.find(local[groups[g].front()])]) continue;  // part of a taller structure
    for (int v : groups[g]) voxel_group[v] = static_cast<int>(g);
  }
  std::vector<std::vector<int>> group_points(groups.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int v = grid.point_voxel[i];
    if (v < 0 || voxel_group[v] < 0) continue;
    const Eigen::Vector3f q = cloud[i].getVector3fMap();
    const double h = frames[owner[v]].model.distance(q);
    if (h > cfg.max_object_height_m || h < object_height_threshold(cfg, (q.cast<double>() - sensor_origin).norm())) continue;
    group_points[voxel_group[v]].push_back(static_cast<int>(i));
  }
  std::vector<Piece> clusters;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (!group_points[g].empty()) clusters.push_back({std::move(group_points[g]), owner[groups[g].front()]});
  }
  return clusters;
}

// Each convex part cut at closed depth steps and colour edges (boundary_cut.h, depth_steps.h,
// colour_edges.h); their window is the bounding box of all the parts' pixels.
std::vector<std::vector<int>> cut_parts_at_boundaries(const Cloud& cloud, std::vector<std::vector<int>> parts,
                                                 const Eigen::Vector3d& sensor_origin, const Config& cfg) {
  const int width = static_cast<int>(cloud.width);
  int u0 = width, v0 = static_cast<int>(cloud.height), u1 = -1, v1 = -1;
  for (const auto& part : parts)
    for (int i : part) {
      u0 = std::min(u0, i % width), u1 = std::max(u1, i % width);
      v0 = std::min(v0, i / width), v1 = std::max(v1, i / width);
    }
  if (u1 < u0) return parts;
  DepthStepParams step_params;
  step_params.sensor = cfg.sensor;
  std::optional<DepthSteps> steps;
  if (cfg.split_depth_steps) steps.emplace(cloud, sensor_origin, step_params, u0, v0, u1, v1);
  std::optional<ColourEdges> colour;
  if (cfg.split_colour_edges) colour.emplace(cloud, u0, v0, u1, v1);
  BoundaryCutParams cut;
  cut.min_part_size_m = ConvexityParams{}.min_part_size_m;
  cut.min_points = cfg.min_cluster_points;
  cut.cluster_tolerance_m = cfg.cluster_tolerance_m;
  const BoundaryTest is_boundary = [&](int a, int offset) {
    return steps && steps->is_step(a, offset) ? Boundary::kDepthStep : Boundary::kNone;
  };
  EdgePixelTest is_edge;
  if (colour) is_edge = [&](int i) { return colour->is_edge(i); };
  std::vector<std::vector<int>> out;
  for (auto& part : parts) {
    for (auto& piece : cut_at_boundaries(cloud, part, sensor_origin, is_boundary, is_edge, cut)) out.push_back(std::move(piece));
  }
  return out;
}

}  // namespace

Segmentation segment(const Cloud& cloud, const Config& cfg, const Eigen::Vector3d& sensor_origin) {
  if (cloud.height <= 1 && cfg.recover_image_grid) {
    if (const auto grid = recover_image_grid(cloud, sensor_origin, cloud.sensor_orientation_)) {
      return to_cloud_indices(cloud, *grid, segment(organized_cloud(cloud, *grid), cfg, sensor_origin), cfg.voxel_size_m);
    }
  }
  Segmentation out;
  const VoxelIndex grid(cloud, cfg.voxel_size_m);
  if (grid.centroids.size() < 3) return out;
  std::vector<char> in_plane;
  const std::vector<PlaneFrame> frames = find_supports(cloud, grid, cfg, sensor_origin, in_plane, out.planes);
  if (frames.empty()) return out;
  std::vector<Piece> clusters = euclidean_clusters(cloud, grid, frames, in_plane, cfg, sensor_origin);

  // Only a single view orients the patch normals (towards its sensor); a merged cloud of several
  // views keeps its Euclidean clusters.
  const bool split = cfg.split_concave && cloud.height > 1;
  std::vector<Piece> pieces;
  for (Piece& cluster : clusters) {
    std::vector<std::vector<int>> parts;
    if (split) parts = split_at_concavities(cloud, cluster.indices, sensor_origin, convexity_params(cfg));
    else parts.push_back(std::move(cluster.indices));
    if (split && (cfg.split_depth_steps || cfg.split_colour_edges))
      parts = cut_parts_at_boundaries(cloud, std::move(parts), sensor_origin, cfg);
    if (split && cfg.split_stacked) {
      TerraceParams tp;
      tp.sensor = cfg.sensor;
      tp.min_points = cfg.min_cluster_points;
      tp.min_size_m = ConvexityParams{}.min_part_size_m;
      Eigen::Vector3d n = frames[cluster.plane].model.n;
      double d = frames[cluster.plane].model.d;
      if (n.dot(sensor_origin) + d < 0) n = -n, d = -d;
      std::vector<std::vector<int>> cut;
      for (auto& p : parts)
        for (auto& piece : split_at_terraces(cloud, std::move(p), n, d, tp)) cut.push_back(std::move(piece));
      parts = std::move(cut);
    }
    for (auto& indices : parts) {
      const int n = static_cast<int>(indices.size());
      if (n >= cfg.min_cluster_points && n <= cfg.max_cluster_points) pieces.push_back({std::move(indices), cluster.plane});
    }
  }
  if (split) pieces = join_container_pieces(cloud, std::move(pieces), out.planes, ContainerParams{});
  if (cfg.join_occluded) pieces = join_occluded_pieces(cloud, std::move(pieces), out.planes, OcclusionParams{});
  for (Piece& piece : pieces) {
    if (static_cast<int>(piece.indices.size()) > cfg.max_cluster_points) continue;
    out.objects.push_back(make_object(cloud, std::move(piece.indices), piece.plane, frames[piece.plane].model.n));
  }
  std::stable_sort(out.objects.begin(), out.objects.end(),
                   [](const ObjectCluster& a, const ObjectCluster& b) { return a.point_count > b.point_count; });
  SupportParams support;
  support.min_object_height_m = cfg.min_object_height_m;
  assign_supports(cloud, out.objects, out.planes, support);
  return out;
}

}  // namespace scenewatch::segmentation
