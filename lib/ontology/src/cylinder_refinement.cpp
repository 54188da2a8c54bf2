#include "scenewatch/ontology/cylinder_refinement.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace scenewatch::ontology {
namespace {

// Two unit vectors completing `axis` to a right-handed orthonormal frame.
void basis(const Eigen::Vector3d& axis, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  const Eigen::Vector3d helper = std::abs(axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u = axis.cross(helper).normalized();
  v = axis.cross(u);
}

double huber_weight(double r, double h) { return std::abs(r) <= h ? 1.0 : h / std::abs(r); }
double huber_loss(double r, double h) { return std::abs(r) <= h ? 0.5 * r * r : h * (std::abs(r) - 0.5 * h); }

struct State {
  Eigen::Vector3d c, a;
  double r;
};

double cost(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& band, const State& s, double h) {
  double total = 0;
  for (const int i : band) {
    const Eigen::Vector3d d = points[static_cast<std::size_t>(i)] - s.c;
    total += huber_loss((d - d.dot(s.a) * s.a).norm() - s.r, h);
  }
  return total;
}

// Points within the band of the cylinder whose normals point away from its axis.
// `excluded` (empty, or one flag per point): points left out.
std::vector<int> select_band(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                             const State& s, const FitConfig& config, const std::vector<char>& excluded = {}) {
  std::vector<int> band;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!excluded.empty() && excluded[i]) continue;
    const Eigen::Vector3d d = points[i] - s.c;
    const Eigen::Vector3d perp = d - d.dot(s.a) * s.a;
    const double dist = perp.norm();
    if (dist < 1e-9 || std::abs(dist - s.r) > config.refine_band_m) continue;
    // Signed: normals face the sensor, so this keeps the outside of the cylinder on the sensor's
    // side, the only part one view can see. Points "behind" the axis (a neighbouring object) and
    // the inside wall of a cup seen over its rim fail it.
    if (!normals.empty() && normals[i].dot(perp / dist) < config.refine_min_normal_cos) continue;
    band.push_back(static_cast<int>(i));
  }
  return band;
}

// Moves c along the axis to the foot of the band's centroid (keeps d.a small: conditioning).
void recenter(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& band, State& s) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : band) mean += points[static_cast<std::size_t>(i)];
  mean /= static_cast<double>(band.size());
  s.c += (mean - s.c).dot(s.a) * s.a;
}

// At most 5 parameters: fixed-capacity Eigen types, no allocation per point.
using Matrix5 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
using Vector5 = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 5, 1>;

// Levenberg-Marquardt on the Huber-weighted radial residuals (IRLS weights per iteration).
// Parameters: (alpha, beta) tilt the axis towards u and v, (tx, ty) move it along u and v, dr.
int levenberg_marquardt(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& band, bool fix_axis,
                        double h, State& s) {
  const int n = fix_axis ? 3 : 5;
  double lambda = 1e-3;
  double current = cost(points, band, s, h);
  int iterations = 0;
  for (; iterations < 50; ++iterations) {
    Eigen::Vector3d u, v;
    basis(s.a, u, v);
    Matrix5 H = Matrix5::Zero(n, n);
    Vector5 g = Vector5::Zero(n);
    for (const int i : band) {
      const Eigen::Vector3d d = points[static_cast<std::size_t>(i)] - s.c;
      const double along = d.dot(s.a);
      const Eigen::Vector3d perp = d - along * s.a;
      const double dist = perp.norm();
      if (dist < 1e-12) continue;
      const Eigen::Vector3d m = perp / dist;
      const double res = dist - s.r;
      // d dist / d alpha = m . d perp / d alpha = -(d.a)(m.u), as m is orthogonal to a.
      Vector5 J(n);
      if (fix_axis) J << -m.dot(u), -m.dot(v), -1.0;
      else J << -along * m.dot(u), -along * m.dot(v), -m.dot(u), -m.dot(v), -1.0;
      const double w = huber_weight(res, h);
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * res * J;
    }
    bool accepted = false;
    Vector5 delta;
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      Matrix5 damped = H;
      damped.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      delta = damped.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      State next = s;
      if (fix_axis) {
        next.c += delta(0) * u + delta(1) * v;
        next.r += delta(2);
      } else {
        next.a = (s.a + delta(0) * u + delta(1) * v).normalized();
        next.c += delta(2) * u + delta(3) * v;
        next.r += delta(4);
      }
      const double trial = cost(points, band, next, h);
      if (trial < current) {
        s = next;
        current = trial;
        lambda = std::max(lambda / 10.0, 1e-9);
        accepted = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted || delta.norm() < 1e-9) break;
  }
  return iterations;
}

}  // namespace

double angular_coverage_deg(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& point,
                            const Eigen::Vector3d& axis) {
  if (points.size() < 2) return 0.0;
  Eigen::Vector3d u, v;
  basis(axis.normalized(), u, v);
  std::vector<double> angles;
  angles.reserve(points.size());
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - point;
    angles.push_back(std::atan2(d.dot(v), d.dot(u)));
  }
  std::sort(angles.begin(), angles.end());
  double largest_gap = angles.front() + 2 * M_PI - angles.back();  // across +-pi
  for (std::size_t i = 1; i < angles.size(); ++i) largest_gap = std::max(largest_gap, angles[i] - angles[i - 1]);
  return 360.0 - largest_gap * 180.0 / M_PI;
}

std::optional<CylinderFit> refine_cylinder(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<Eigen::Vector3d>& normals, const CylinderGuess& guess,
                                           bool fix_axis, const FitConfig& config, const std::vector<char>& untrusted) {
  State s{guess.point, guess.axis.normalized(), guess.radius_m};
  if (!s.c.allFinite() || !s.a.allFinite() || !(s.r > 0)) return std::nullopt;
  CylinderFit fit;
  std::vector<int> band;
  for (int round = 0; round < std::max(1, config.refine_rounds); ++round) {
    band = select_band(points, normals, s, config, untrusted);
    // Too few trusted points (a small or thin object, all near an edge): fit on all of them.
    if (band.size() < static_cast<std::size_t>(config.min_points) && !untrusted.empty()) {
      band = select_band(points, normals, s, config);
    }
    if (band.size() < static_cast<std::size_t>(config.min_points)) return std::nullopt;
    recenter(points, band, s);
    fit.iterations += levenberg_marquardt(points, band, fix_axis, config.huber_m, s);
    if (!(s.r > 0) || !std::isfinite(s.r) || !s.c.allFinite() || !s.a.allFinite()) return std::nullopt;
  }
  band = select_band(points, normals, s, config);
  if (band.size() < static_cast<std::size_t>(config.min_points)) return std::nullopt;

  double lo = std::numeric_limits<double>::infinity(), hi = -lo, squares = 0;
  std::vector<Eigen::Vector3d> seen;
  seen.reserve(band.size());
  for (const int i : band) {
    const Eigen::Vector3d& p = points[static_cast<std::size_t>(i)];
    const Eigen::Vector3d d = p - s.c;
    const double along = d.dot(s.a);
    lo = std::min(lo, along);
    hi = std::max(hi, along);
    const double res = (d - along * s.a).norm() - s.r;
    squares += res * res;
    seen.push_back(p);
  }
  fit.axis = s.a;
  fit.center = s.c + 0.5 * (lo + hi) * s.a;
  fit.radius_m = s.r;
  fit.height_m = hi - lo;
  fit.rms_m = std::sqrt(squares / static_cast<double>(band.size()));
  fit.coverage_deg = angular_coverage_deg(seen, s.c, s.a);
  fit.inliers = band.size();
  fit.axis_fixed = fix_axis;
  fit.indices = std::move(band);
  return fit;
}

std::optional<CylinderGuess> upright_guess(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& up,
                                           const FitConfig& config) {
  const Eigen::Vector3d a = up.normalized();
  Eigen::Vector3d u, v;
  basis(a, u, v);
  // Kasa: x^2 + y^2 + D x + E y + F = 0, linear least squares.
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::size_t used = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!normals.empty() && std::abs(normals[i].dot(a)) > 0.5) continue;  // tops and bottoms
    origin += points[i];
    ++used;
  }
  if (used < static_cast<std::size_t>(config.min_points)) return std::nullopt;
  origin /= static_cast<double>(used);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!normals.empty() && std::abs(normals[i].dot(a)) > 0.5) continue;
    const Eigen::Vector3d d = points[i] - origin;
    const double x = d.dot(u), y = d.dot(v);
    const Eigen::Vector3d row(x, y, 1.0);
    AtA += row * row.transpose();
    Atb += row * -(x * x + y * y);
  }
  const Eigen::Vector3d def = AtA.ldlt().solve(Atb);
  const double cx = -def(0) / 2, cy = -def(1) / 2;
  const double r2 = cx * cx + cy * cy - def(2);
  if (!def.allFinite() || !(r2 > 0)) return std::nullopt;
  return CylinderGuess{origin + cx * u + cy * v, a, std::sqrt(r2)};
}

}  // namespace scenewatch::ontology
