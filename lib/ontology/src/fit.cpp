// The facade of primitive fitting: validation, subsampling, normals, shape detection, refinement.
#include "scenewatch/ontology/fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "depth_edges.h"
#include "efficient_ransac.h"
#include "normals.h"
#include "scenewatch/ontology/cylinder_refinement.h"

namespace scenewatch::ontology {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

Error bad(const std::string& key, const std::string& what) { return invalid_argument("ontology." + key + " " + what); }

}  // namespace

Status validate(const FitConfig& c) {
  if (c.normal_neighbours < 3) return bad("normal_neighbours", "must be at least 3");
  if (c.min_points < 10) return bad("min_points", "must be at least 10");
  if (c.max_points < c.min_points) return bad("max_points", "must be at least min_points");
  if (!(c.epsilon_m > 0)) return bad("epsilon_m", "must be positive");
  if (!(c.cluster_epsilon_m > 0)) return bad("cluster_epsilon_m", "must be positive");
  if (!(c.normal_threshold >= 0 && c.normal_threshold <= 1)) return bad("normal_threshold", "must be in [0, 1]");
  if (!(c.min_shape_fraction > 0 && c.min_shape_fraction <= 1)) return bad("min_shape_fraction", "must be in (0, 1]");
  if (!(c.probability > 0 && c.probability < 1)) return bad("probability", "must be in (0, 1)");
  if (!(c.upright_tolerance_deg >= 0 && c.upright_tolerance_deg <= 90)) return bad("upright_tolerance_deg", "must be in [0, 90]");
  if (!(c.refine_band_m > 0)) return bad("refine_band_m", "must be positive");
  if (!(c.refine_min_normal_cos >= 0 && c.refine_min_normal_cos <= 1)) return bad("refine_min_normal_cos", "must be in [0, 1]");
  if (c.refine_rounds < 1) return bad("refine_rounds", "must be at least 1");
  if (!(c.huber_m > 0)) return bad("huber_m", "must be positive");
  if (!(c.edge_margin_deg >= 0 && c.edge_margin_deg <= 10)) return bad("edge_margin_deg", "must be in [0, 10]");
  if (!(c.edge_jump_m > 0)) return bad("edge_jump_m", "must be positive");
  if (!(c.cylinder_max_cone_deg >= 0 && c.cylinder_max_cone_deg < 90)) return bad("cylinder_max_cone_deg", "must be in [0, 90)");
  return {};
}

Result<ObjectFit> fit_object(const Cloud& cloud, const std::vector<int>& indices, const FitConfig& config,
                             const std::optional<Eigen::Vector3d>& up, const Eigen::Vector3d& sensor_origin) {
  if (Status s = validate(config); !s) return s.error();
  if (up && !(up->allFinite() && up->norm() > 0)) return invalid_argument("fit: the up vector is zero or not finite");
  std::vector<int> valid;
  valid.reserve(indices.size());
  for (const int i : indices) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.points.size()) {
      return invalid_argument("fit: point index " + std::to_string(i) + " is outside the cloud (" +
                              std::to_string(cloud.points.size()) + " points)");
    }
    if (is_valid(cloud.points[static_cast<std::size_t>(i)])) valid.push_back(i);
  }
  if (valid.size() < static_cast<std::size_t>(config.min_points)) {
    return invalid_argument("fit: the object has " + std::to_string(valid.size()) + " valid points (" +
                            std::to_string(indices.size() - valid.size()) + " of " + std::to_string(indices.size()) +
                            " not finite); at least " + std::to_string(config.min_points) + " are needed");
  }
  ObjectFit out;
  out.points = valid.size();
  // Evenly spaced points, max_points of them (a fractional stride: 3184 points become 3000, not
  // every second one): a bounded fit time for near, dense objects.
  const std::size_t m = std::min(valid.size(), static_cast<std::size_t>(config.max_points));
  std::vector<int> used(m);
  for (std::size_t i = 0; i < m; ++i) used[i] = valid[i * valid.size() / m];

  auto t0 = Clock::now();
  const int k = std::min<int>(config.normal_neighbours, static_cast<int>(used.size()) - 1);
  const std::vector<Eigen::Vector3d> all_normals = config.normal_search == NormalSearch::kGrid
                                                       ? detail::estimate_normals(cloud, used, k, sensor_origin)
                                                       : detail::estimate_normals_kdtree(cloud, used, k, sensor_origin);
  std::vector<int> kept;  // cloud indices of points with a normal
  std::vector<Eigen::Vector3d> points, normals;
  for (std::size_t i = 0; i < used.size(); ++i) {
    if (!all_normals[i].allFinite()) continue;
    kept.push_back(used[i]);
    points.push_back(cloud.points[static_cast<std::size_t>(used[i])].getVector3fMap().cast<double>());
    normals.push_back(all_normals[i]);
  }
  out.normals_ms = ms_since(t0);
  out.points_detected = points.size();
  if (points.size() < static_cast<std::size_t>(config.min_points)) {
    return invalid_argument("fit: only " + std::to_string(points.size()) + " points have a surface normal; at least " +
                            std::to_string(config.min_points) + " are needed");
  }

  t0 = Clock::now();
  out.shapes = detail::detect_shapes(points, normals, config);
  int largest_cylinder = -1;
  for (auto& shape : out.shapes) {
    double squares = 0;
    for (int& i : shape.indices) {
      const double d = distance_to_surface(shape, points[static_cast<std::size_t>(i)]);
      squares += d * d;
    }
    shape.rms_m = shape.indices.empty() ? 0.0 : std::sqrt(squares / static_cast<double>(shape.indices.size()));
  }
  // Indices stay positions in `points` until the refinement has used them.
  std::stable_sort(out.shapes.begin(), out.shapes.end(),
                   [](const Primitive& a, const Primitive& b) { return a.indices.size() > b.indices.size(); });
  if (!out.shapes.empty()) out.best = 0;
  // A cone of nearly no angle is a cylinder that CGAL happened to explain as a cone (a straight cup).
  for (std::size_t s = 0; s < out.shapes.size(); ++s) {
    const Primitive& shape = out.shapes[s];
    if (shape.kind == PrimitiveKind::kCylinder ||
        (shape.kind == PrimitiveKind::kCone && shape.half_angle_deg <= config.cylinder_max_cone_deg)) {
      largest_cylinder = static_cast<int>(s);
      break;
    }
  }
  out.detection_ms = ms_since(t0);

  t0 = Clock::now();
  const std::vector<char> near_edge = detail::near_depth_edge(cloud, kept, config.edge_margin_deg, config.edge_jump_m,
                                                                  sensor_origin);
  const bool upright = config.axis_prior == AxisPrior::kUpright && up.has_value();
  const Eigen::Vector3d up_unit = up ? up->normalized() : Eigen::Vector3d::UnitZ();
  std::optional<CylinderFit> cylinder;
  if (largest_cylinder >= 0) {
    const Primitive& c = out.shapes[static_cast<std::size_t>(largest_cylinder)];
    CylinderGuess guess{c.point, c.direction, c.radius_m};
    // The point on the axis level with the shape's points: holding the axis upright turns it about
    // this point (a cone's apex may be metres away).
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    double distance_sum = 0;
    for (const int i : c.indices) {
      const Eigen::Vector3d d = points[static_cast<std::size_t>(i)] - c.point;
      centroid += points[static_cast<std::size_t>(i)];
      distance_sum += (d - d.dot(c.direction) * c.direction).norm();
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, c.indices.size()));
    guess.point = c.point + (centroid / n - c.point).dot(c.direction) * c.direction;
    if (c.kind == PrimitiveKind::kCone) guess.radius_m = distance_sum / n;  // its mean radius
    const double tilt_deg = std::acos(std::min(1.0, std::abs(c.direction.dot(up_unit)))) * 180.0 / M_PI;
    const bool fix = upright && tilt_deg <= config.upright_tolerance_deg;
    if (fix) guess.axis = up_unit;
    cylinder = refine_cylinder(points, normals, guess, fix, config, near_edge);
  } else if (upright && config.detect_cylinder) {
    if (auto guess = upright_guess(points, normals, up_unit, config)) {
      cylinder = refine_cylinder(points, normals, *guess, true, config, near_edge);
      if (cylinder) cylinder->from_detection = false;
    }
  }
  if (cylinder) {
    if (up && cylinder->axis.dot(up_unit) < 0) cylinder->axis = -cylinder->axis;
    for (int& i : cylinder->indices) i = kept[static_cast<std::size_t>(i)];
    out.cylinder = std::move(cylinder);
  }
  for (auto& shape : out.shapes)
    for (int& i : shape.indices) i = kept[static_cast<std::size_t>(i)];
  out.refinement_ms = ms_since(t0);
  out.sample_points = std::move(points);
  out.sample_normals = std::move(normals);
  out.sample_near_edge = near_edge;
  return out;
}

}  // namespace scenewatch::ontology
