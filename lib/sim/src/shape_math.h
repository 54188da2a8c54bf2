#pragma once
// Ray-primitive intersection as inline functions, so that the ray caster's per-pixel loop can
// inline them; shapes.cpp exposes the same code as sim::intersect.
#include <algorithm>
#include <cmath>

#include "scenewatch/sim/shapes.h"

namespace scenewatch::sim::detail {

using Eigen::Vector2d;
using Eigen::Vector3d;


using Eigen::Vector2d;
using Eigen::Vector3d;

/// Keeps the nearest candidate hit in (t_min, best->t).
struct Nearest {
  double t_min;
  double t_best;
  Vector3d normal = Vector3d::UnitZ();
  bool found = false;
  void offer(double t, const Vector3d& n) {
    if (t > t_min && t < t_best) {
      t_best = t;
      normal = n;
      found = true;
    }
  }
};

/// Lateral surface of a frustum rho(z) = r0 + s z for z in [z0, z1]; outward = +1 for the outer
/// surface of a solid, -1 for the inner surface of a vessel (the solid is outside the surface).
inline void lateral(const Vector3d& o, const Vector3d& d, double r0, double s, double z0, double z1, double outward,
             Nearest* best) {
  const double k = r0 + s * o.z();
  const double a = d.x() * d.x() + d.y() * d.y() - s * s * d.z() * d.z();
  const double b = o.x() * d.x() + o.y() * d.y() - s * k * d.z();
  const double c = o.x() * o.x() + o.y() * o.y() - k * k;
  double roots[2];
  int n = 0;
  if (std::abs(a) < 1e-14) {
    if (std::abs(b) > 1e-14) roots[n++] = -c / (2.0 * b);
  } else {
    const double disc = b * b - a * c;
    if (disc < 0.0) return;
    const double sq = std::sqrt(disc);
    roots[n++] = (-b - sq) / a;
    roots[n++] = (-b + sq) / a;
  }
  for (int i = 0; i < n; ++i) {
    const double t = roots[i];
    if (t <= best->t_min || t >= best->t_best) continue;
    const Vector3d p = o + t * d;
    if (p.z() < z0 || p.z() > z1) continue;
    const double rho = r0 + s * p.z();
    if (rho < 0.0) continue;  // the other nappe of the cone
    Vector3d n3(p.x(), p.y(), -s * rho);
    const double len = n3.norm();
    if (len <= 0.0) n3 = Vector3d::UnitZ(); else n3 /= len;
    best->offer(t, outward * n3);
  }
}

/// Horizontal disc or annulus at height z with inner/outer radius; normal along +z or -z.
inline void disc(const Vector3d& o, const Vector3d& d, double z, double r_in, double r_out, double nz, Nearest* best) {
  if (d.z() == 0.0) return;
  const double t = (z - o.z()) / d.z();
  if (t <= best->t_min || t >= best->t_best) return;
  const double x = o.x() + t * d.x();
  const double y = o.y() + t * d.y();
  const double rho2 = x * x + y * y;
  if (rho2 > r_out * r_out || rho2 < r_in * r_in) return;
  best->offer(t, Vector3d(0, 0, nz));
}

inline void sphere(const Vector3d& o, const Vector3d& d, const Vector3d& center, double r, double z_lo, double z_hi,
            Nearest* best) {
  const Vector3d oc = o - center;
  const double a = d.squaredNorm();
  const double b = oc.dot(d);
  const double c = oc.squaredNorm() - r * r;
  const double disc = b * b - a * c;
  if (disc < 0.0 || a <= 0.0) return;
  const double sq = std::sqrt(disc);
  for (double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (t <= best->t_min || t >= best->t_best) continue;
    const Vector3d p = o + t * d;
    if (p.z() < z_lo || p.z() > z_hi) continue;
    best->offer(t, (p - center) / r);
  }
}

inline void box(const Vector3d& o, const Vector3d& d, const Vector3d& size, Nearest* best) {
  const double lo[3] = {-0.5 * size.x(), -0.5 * size.y(), 0.0};
  const double hi[3] = {0.5 * size.x(), 0.5 * size.y(), size.z()};
  // Slabs; the near and far crossings only keep their axis, the normal is built for the one hit.
  double t_near = -1e300, t_far = 1e300;
  int axis_near = 0, axis_far = 0;
  for (int i = 0; i < 3; ++i) {
    const double di = d[i], oi = o[i];
    if (di == 0.0) {
      if (oi < lo[i] || oi > hi[i]) return;
      continue;
    }
    const double inv = 1.0 / di;
    const double ta = (lo[i] - oi) * inv, tb = (hi[i] - oi) * inv;
    const double t0 = di > 0 ? ta : tb, t1 = di > 0 ? tb : ta;
    if (t0 > t_near) { t_near = t0; axis_near = i; }
    if (t1 < t_far) { t_far = t1; axis_far = i; }
  }
  if (t_near > t_far) return;
  if (t_near > best->t_min && t_near < best->t_best) {
    Vector3d n = Vector3d::Zero();
    n[axis_near] = d[axis_near] > 0 ? -1.0 : 1.0;
    best->offer(t_near, n);
  } else if (t_far > best->t_min && t_far < best->t_best) {
    Vector3d n = Vector3d::Zero();
    n[axis_far] = d[axis_far] > 0 ? 1.0 : -1.0;
    best->offer(t_far, n);
  }
}

inline bool intersect_inline(const Shape& shape, const Vector3d& o, const Vector3d& d, double t_min, double t_max,
                             ShapeHit* hit) {
  Nearest best{t_min, t_max};
  switch (shape.kind) {
    case ShapeKind::kBox:
      box(o, d, shape.size_m, &best);
      break;
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum: {
      const double h = shape.height_m;
      const double r0 = shape.radius_m;
      const double r1 = shape.top_radius_or_radius_m();
      const double s = (r1 - r0) / h;
      lateral(o, d, r0, s, 0.0, h, 1.0, &best);
      disc(o, d, 0.0, 0.0, r0, -1.0, &best);
      if (shape.open_top) {
        const double w = shape.wall_m;
        lateral(o, d, r0 - w, s, w, h, -1.0, &best);
        disc(o, d, h, std::max(0.0, r1 - w), r1, 1.0, &best);
        disc(o, d, w, 0.0, std::max(0.0, r0 - w + s * w), 1.0, &best);
      } else if (r1 > 0.0) {
        disc(o, d, h, 0.0, r1, 1.0, &best);
      }
      break;
    }
    case ShapeKind::kSphere:
      sphere(o, d, Vector3d(0, 0, shape.radius_m), shape.radius_m, -1e300, 1e300, &best);
      break;
    case ShapeKind::kCapsule: {
      const double r = shape.radius_m;
      const double z0 = r, z1 = r + shape.height_m;
      lateral(o, d, r, 0.0, z0, z1, 1.0, &best);
      sphere(o, d, Vector3d(0, 0, z0), r, -1e300, z0, &best);
      sphere(o, d, Vector3d(0, 0, z1), r, z1, 1e300, &best);
      break;
    }
  }
  if (!best.found) return false;
  hit->t = best.t_best;
  hit->normal = best.normal;
  return true;
}

}  // namespace scenewatch::sim::detail
