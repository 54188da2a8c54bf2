// A class's primitive fitted to one object: cylinder (from fit_object's refined cylinder),
// frustum (Gauss-Newton on the radius as a linear function of height, axis held), sphere
// (algebraic fit, then geometric Gauss-Newton), upright box (yaw from the side normals).
#include "scenewatch/ontology/shape_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "scenewatch/ontology/cylinder_refinement.h"

namespace scenewatch::ontology {
namespace {

constexpr double kBandM = 0.01;        // points this close to the surface count for rms
constexpr double kHuberM = 0.003;      // robust weights of the Gauss-Newton fits
constexpr double kDeg = 180.0 / M_PI;
constexpr double kUprightStartDeg = 25.0;  // fit_object's upright tolerance: a cylinder tilted more
                                           // does not start a frustum

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// Two unit vectors completing `a` to a right-handed frame.
void basis(const Eigen::Vector3d& a, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  e1 = (std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(a).normalized();
  e2 = a.cross(e1);
}

double huber_weight(double r) { return std::abs(r) <= kHuberM ? 1.0 : kHuberM / std::abs(r); }

/// Distance from (x, y) to the segment (ax, ay)-(bx, by) in 2D, and the closest point's parameter.
double segment_distance(double x, double y, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(x - (ax + t * dx), y - (ay + t * dy));
}

/// Fills the fit's rms (points within kBandM) and, for round shapes, nothing else.
void measure_rms(ShapeFit& fit, const std::vector<Eigen::Vector3d>& points) {
  double squares = 0;
  std::size_t n = 0;
  for (const auto& p : points) {
    const double d = surface_distance(fit, p);
    if (d <= kBandM) {
      squares += d * d;
      ++n;
    }
  }
  fit.rms_m = n ? std::sqrt(squares / static_cast<double>(n)) : kBandM;
}

/// Height extent along the axis (1st and 99th percentile): sets center (moved along the axis) and
/// height_m; returns the offsets of bottom and top from the old centre.
std::pair<double, double> height_extent(ShapeFit& fit, const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> t;
  t.reserve(points.size());
  for (const auto& p : points) t.push_back((p - fit.center).dot(fit.axis));
  const double lo = percentile(t, 0.01), hi = percentile(t, 0.99);
  fit.center += 0.5 * (lo + hi) * fit.axis;
  fit.height_m = hi - lo;
  return {lo, hi};
}

// `near_edge` (empty, or one flag per point): points near a depth edge, whose biased normals do
// not count as the inside wall (the far rim of a can's lid seen at a grazing angle would).
void measure_vessel(ShapeFit& fit, const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                    const std::vector<char>& near_edge) {
  const double h = 0.5 * fit.height_m;
  std::size_t inner = 0;
  std::vector<Eigen::Vector3d> side;
  double squares = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = points[i] - fit.center;
    const double t = d.dot(fit.axis);
    const Eigen::Vector3d radial = d - t * fit.axis;
    const double rho = radial.norm();
    const double r = fit.bottom_radius_m + (t + h) / std::max(1e-9, fit.height_m) * (fit.top_radius_m - fit.bottom_radius_m);
    if (rho <= 1e-9) continue;
    const double outward = normals[i].dot(radial / rho);
    if (std::abs(rho - r) <= kBandM && outward > 0.5) {
      side.push_back(points[i]);
      squares += (rho - r) * (rho - r);
    }
    // The inside wall, seen over the rim: inside the solid, above its lower fifth, facing the axis.
    const bool trusted = near_edge.size() != points.size() || !near_edge[i];
    if (trusted && rho < r - 0.003 && rho > 0.3 * r && t > -h + 0.2 * fit.height_m && outward < -0.5) ++inner;
  }
  fit.inner_fraction = points.empty() ? 0 : static_cast<double>(inner) / static_cast<double>(points.size());
  fit.coverage_deg = side.size() >= 3 ? angular_coverage_deg(side, fit.center, fit.axis) : 0.0;
  fit.rms_m = side.empty() ? kBandM : std::sqrt(squares / static_cast<double>(side.size()));
}

std::optional<ShapeFit> fit_cylinder(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                                     const ObjectFit& object, const Eigen::Vector3d& up) {
  if (!object.cylinder) return std::nullopt;
  ShapeFit fit;
  fit.shape = ClassShape::kCylinder;
  fit.center = object.cylinder->center;
  fit.axis = object.cylinder->axis.dot(up) < 0 ? Eigen::Vector3d(-object.cylinder->axis) : object.cylinder->axis;
  fit.radius_m = fit.bottom_radius_m = fit.top_radius_m = object.cylinder->radius_m;
  height_extent(fit, points);
  fit.axis_tilt_deg = std::acos(std::min(1.0, std::abs(fit.axis.dot(up)))) * kDeg;
  measure_vessel(fit, points, normals, object.sample_near_edge);
  return fit;
}

std::optional<ShapeFit> fit_frustum(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                                    const ObjectFit& object, const Eigen::Vector3d& up) {
  auto start = fit_cylinder(points, normals, object, up);
  if (!start || start->axis_tilt_deg > kUprightStartDeg) {
    // A wide, flaring vessel (a bowl) is often not detected as an upright cylinder: start from the
    // upright circle fit of its side points instead.
    ObjectFit upright;
    FitConfig config;
    if (auto guess = upright_guess(points, normals, up, config)) upright.cylinder = refine_cylinder(points, normals, *guess, true, config);
    if (upright.cylinder) start = fit_cylinder(points, normals, upright, up);
  }
  if (!start) return std::nullopt;
  ShapeFit fit = *start;
  fit.shape = ClassShape::kFrustum;
  Eigen::Vector3d e1, e2;
  basis(fit.axis, e1, e2);
  // The side points: near the starting cylinder, normals facing outwards.
  std::vector<Eigen::Vector3d> q;  // (u, v, t) in the frame (e1, e2, axis) about the centre
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = points[i] - fit.center;
    const double t = d.dot(fit.axis);
    const Eigen::Vector3d radial = d - t * fit.axis;
    const double rho = radial.norm();
    if (rho < 1e-9 || std::abs(rho - fit.radius_m) > 1.5 * kBandM || normals[i].dot(radial / rho) < 0.5) continue;
    q.emplace_back(d.dot(e1), d.dot(e2), t);
  }
  if (q.size() < 20) return std::nullopt;
  // Gauss-Newton with Huber weights on r_i = |(u, v) - c| - (a + b t) over (c_u, c_v, a, b).
  Eigen::Vector4d x(0, 0, fit.radius_m, 0);
  for (int iteration = 0; iteration < 15; ++iteration) {
    Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
    Eigen::Vector4d Jtr = Eigen::Vector4d::Zero();
    for (const auto& p : q) {
      const Eigen::Vector2d d(p.x() - x(0), p.y() - x(1));
      const double rho = d.norm();
      if (rho < 1e-9) continue;
      const double r = rho - (x(2) + x(3) * p.z());
      const Eigen::Vector4d J(-d.x() / rho, -d.y() / rho, -1.0, -p.z());
      const double w = huber_weight(r);
      JtJ += w * J * J.transpose();
      Jtr += w * J * r;
    }
    const Eigen::Vector4d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) return std::nullopt;
    x += step;
    if (step.norm() < 1e-7) break;
  }
  fit.center += x(0) * e1 + x(1) * e2;
  const double h = 0.5 * fit.height_m;
  fit.bottom_radius_m = x(2) - x(3) * h;
  fit.top_radius_m = x(2) + x(3) * h;
  if (!(fit.bottom_radius_m > 0 && fit.top_radius_m > 0)) return std::nullopt;
  fit.radius_m = 0.5 * (fit.bottom_radius_m + fit.top_radius_m);
  fit.taper_deg = std::atan(x(3)) * kDeg;
  measure_vessel(fit, points, normals, object.sample_near_edge);
  return fit;
}

std::optional<ShapeFit> fit_sphere(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up) {
  if (points.size() < 10) return std::nullopt;
  // Algebraic: |p|^2 = 2 c.p + (r^2 - |c|^2), linear in (c, k).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix4d AtA = Eigen::Matrix4d::Zero();
  Eigen::Vector4d Atb = Eigen::Vector4d::Zero();
  for (const auto& p0 : points) {
    const Eigen::Vector3d p = p0 - mean;
    const Eigen::Vector4d a(2 * p.x(), 2 * p.y(), 2 * p.z(), 1.0);
    AtA += a * a.transpose();
    Atb += a * p.squaredNorm();
  }
  const Eigen::Vector4d s = AtA.ldlt().solve(Atb);
  Eigen::Vector3d c = s.head<3>();
  double r2 = s(3) + c.squaredNorm();
  if (!s.allFinite() || !(r2 > 0)) return std::nullopt;
  double r = std::sqrt(r2);
  c += mean;
  // Geometric Gauss-Newton with Huber weights on |p - c| - r.
  for (int iteration = 0; iteration < 15; ++iteration) {
    Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
    Eigen::Vector4d Jtr = Eigen::Vector4d::Zero();
    for (const auto& p : points) {
      const Eigen::Vector3d d = p - c;
      const double n = d.norm();
      if (n < 1e-9) continue;
      const double res = n - r;
      Eigen::Vector4d J;
      J << -d / n, -1.0;
      const double w = huber_weight(res);
      JtJ += w * J * J.transpose();
      Jtr += w * J * res;
    }
    const Eigen::Vector4d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) return std::nullopt;
    c += step.head<3>();
    r += step(3);
    if (step.norm() < 1e-7) break;
  }
  if (!(r > 0) || !std::isfinite(r)) return std::nullopt;
  ShapeFit fit;
  fit.shape = ClassShape::kSphere;
  fit.center = c;
  fit.axis = up;
  fit.radius_m = fit.bottom_radius_m = fit.top_radius_m = r;
  std::vector<double> heights;
  for (const auto& p : points) heights.push_back(p.dot(up));
  fit.height_m = percentile(heights, 0.99) - percentile(heights, 0.01);  // the seen extent, not 2 r
  measure_rms(fit, points);
  std::vector<Eigen::Vector3d> near;
  for (const auto& p : points)
    if (surface_distance(fit, p) <= kBandM) near.push_back(p);
  fit.coverage_deg = near.size() >= 3 ? angular_coverage_deg(near, c, up) : 0.0;
  return fit;
}

std::optional<ShapeFit> fit_box(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                                const Eigen::Vector3d& up) {
  Eigen::Vector3d e1, e2;
  basis(up, e1, e2);
  // Yaw of the side faces: the horizontal normals' directions folded four times (faces at 90 degrees).
  double c4 = 0, s4 = 0;
  std::size_t sides = 0;
  for (const auto& n : normals) {
    if (std::abs(n.dot(up)) > 0.3) continue;
    const double phi = std::atan2(n.dot(e2), n.dot(e1));
    c4 += std::cos(4 * phi);
    s4 += std::sin(4 * phi);
    ++sides;
  }
  if (sides < 20) return std::nullopt;
  const double yaw = 0.25 * std::atan2(s4, c4);
  const double alignment = std::hypot(c4, s4) / static_cast<double>(sides);
  Eigen::Vector3d x = std::cos(yaw) * e1 + std::sin(yaw) * e2;
  Eigen::Vector3d y = up.cross(x);
  std::vector<double> px, py, pz;
  for (const auto& p : points) {
    px.push_back(p.dot(x));
    py.push_back(p.dot(y));
    pz.push_back(p.dot(up));
  }
  const double x0 = percentile(px, 0.01), x1 = percentile(px, 0.99);
  const double y0 = percentile(py, 0.01), y1 = percentile(py, 0.99);
  const double z0 = percentile(pz, 0.01), z1 = percentile(pz, 0.99);
  ShapeFit fit;
  fit.shape = ClassShape::kBox;
  fit.axis = up;
  fit.center = 0.5 * (x0 + x1) * x + 0.5 * (y0 + y1) * y + 0.5 * (z0 + z1) * up;
  fit.height_m = z1 - z0;
  fit.size_m = Eigen::Vector2d(x1 - x0, y1 - y0);
  fit.x_axis = x;
  if (fit.size_m.x() > fit.size_m.y()) {
    fit.size_m = Eigen::Vector2d(fit.size_m.y(), fit.size_m.x());
    fit.x_axis = y;
  }
  fit.coverage_deg = 360;
  fit.side_alignment = alignment;
  measure_rms(fit, points);
  return fit;
}

}  // namespace

double surface_distance(const ShapeFit& fit, const Eigen::Vector3d& p, Eigen::Vector3d* normal) {
  const Eigen::Vector3d d = p - fit.center;
  switch (fit.shape) {
    case ClassShape::kSphere: {
      const double n = d.norm();
      if (normal) *normal = n > 1e-12 ? Eigen::Vector3d(d / n) : fit.axis;
      return std::abs(n - fit.radius_m);
    }
    case ClassShape::kBox: {
      const Eigen::Vector3d y = fit.axis.cross(fit.x_axis);
      const Eigen::Vector3d q(d.dot(fit.x_axis), d.dot(y), d.dot(fit.axis));
      const Eigen::Vector3d half(0.5 * fit.size_m.x(), 0.5 * fit.size_m.y(), 0.5 * fit.height_m);
      const Eigen::Vector3d excess = q.cwiseAbs() - half;
      int i = 0;
      excess.maxCoeff(&i);
      if (normal) {
        const Eigen::Vector3d axes[3] = {fit.x_axis, y, fit.axis};
        *normal = q(i) >= 0 ? axes[i] : Eigen::Vector3d(-axes[i]);
      }
      if (excess.maxCoeff() <= 0) return -excess.maxCoeff();
      return excess.cwiseMax(0.0).norm();
    }
    case ClassShape::kCylinder:
    case ClassShape::kFrustum: {
      const double t = d.dot(fit.axis);
      const Eigen::Vector3d radial = d - t * fit.axis;
      const double rho = radial.norm();
      const double h = 0.5 * fit.height_m, rb = fit.bottom_radius_m, rt = fit.top_radius_m;
      const double side = segment_distance(rho, t, rb, -h, rt, h);
      const double bottom = segment_distance(rho, t, 0, -h, rb, -h);
      const double top = segment_distance(rho, t, 0, h, rt, h);
      if (normal) {
        if (side <= bottom && side <= top) {
          // The side's outward normal in the (rho, t) plane: perpendicular to (rt - rb, 2h).
          const Eigen::Vector2d n2 = Eigen::Vector2d(2 * h, -(rt - rb)).normalized();
          const Eigen::Vector3d out = rho > 1e-12 ? Eigen::Vector3d(radial / rho) : Eigen::Vector3d::Zero();
          *normal = n2.x() * out + n2.y() * fit.axis;
        } else {
          *normal = bottom < top ? Eigen::Vector3d(-fit.axis) : fit.axis;
        }
      }
      return std::min({side, bottom, top});
    }
  }
  return d.norm();
}

double explained_fraction(const ShapeFit& fit, const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector3d>& normals, double distance_m) {
  if (points.empty()) return 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d surface_normal;
    if (surface_distance(fit, points[i], &surface_normal) > distance_m) continue;
    if (i < normals.size() && std::abs(normals[i].dot(surface_normal)) < 0.85) continue;
    ++n;
  }
  return static_cast<double>(n) / static_cast<double>(points.size());
}

std::optional<ShapeFit> fit_shape(ClassShape shape, const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& normals, const ObjectFit& object,
                                  const Eigen::Vector3d& up_in) {
  const Eigen::Vector3d up = up_in.normalized();
  switch (shape) {
    case ClassShape::kCylinder: return fit_cylinder(points, normals, object, up);
    case ClassShape::kFrustum: return fit_frustum(points, normals, object, up);
    case ClassShape::kSphere: return fit_sphere(points, up);
    case ClassShape::kBox: return fit_box(points, normals, up);
  }
  return std::nullopt;
}

}  // namespace scenewatch::ontology
