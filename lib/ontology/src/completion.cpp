#include "scenewatch/ontology/completion.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <Eigen/Geometry>

namespace scenewatch::ontology {
namespace {

int steps(double length_m, double spacing_m) { return std::max(1, static_cast<int>(std::ceil(length_m / spacing_m))); }

/// A disc of radius r at `center` perpendicular to `axis`, in rings.
void disc(std::vector<Eigen::Vector3d>& out, const Eigen::Vector3d& center, const Eigen::Vector3d& e1,
          const Eigen::Vector3d& e2, double r, double spacing) {
  out.push_back(center);
  const int rings = steps(r, spacing);
  for (int i = 1; i <= rings; ++i) {
    const double rho = r * i / rings;
    const int n = steps(2 * M_PI * rho, spacing);
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * k / n;
      out.push_back(center + rho * (std::cos(a) * e1 + std::sin(a) * e2));
    }
  }
}

}  // namespace

std::vector<Eigen::Vector3d> complete_surface(const ShapeFit& fit, double spacing, bool open_top) {
  assert(spacing > 0);
  // A class may allow objects of up to 2 m: coarser spacing beyond kMaxCompletedPoints.
  double area = 0;
  switch (fit.shape) {
    case ClassShape::kCylinder:
    case ClassShape::kFrustum:
      area = M_PI * (fit.bottom_radius_m + fit.top_radius_m) * fit.height_m +
             M_PI * (fit.bottom_radius_m * fit.bottom_radius_m + fit.top_radius_m * fit.top_radius_m);
      break;
    case ClassShape::kSphere: area = 4 * M_PI * fit.radius_m * fit.radius_m; break;
    case ClassShape::kBox:
      area = 2 * (fit.size_m.x() * fit.size_m.y() + (fit.size_m.x() + fit.size_m.y()) * fit.height_m);
      break;
  }
  spacing = std::max(spacing, std::sqrt(area / static_cast<double>(kMaxCompletedPoints)));
  std::vector<Eigen::Vector3d> out;
  const Eigen::Vector3d a = fit.axis.normalized();
  const Eigen::Vector3d e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  const double h = 0.5 * fit.height_m;
  switch (fit.shape) {
    case ClassShape::kCylinder:
    case ClassShape::kFrustum: {
      const int rows = steps(fit.height_m, spacing);
      for (int i = 0; i <= rows; ++i) {
        const double f = static_cast<double>(i) / rows;
        const double r = fit.bottom_radius_m + f * (fit.top_radius_m - fit.bottom_radius_m);
        const Eigen::Vector3d c = fit.center + (-h + f * fit.height_m) * a;
        const int n = steps(2 * M_PI * r, spacing);
        for (int k = 0; k < n; ++k) {
          const double t = 2 * M_PI * k / n;
          out.push_back(c + r * (std::cos(t) * e1 + std::sin(t) * e2));
        }
      }
      disc(out, fit.center - h * a, e1, e2, fit.bottom_radius_m, spacing);
      if (!open_top) disc(out, fit.center + h * a, e1, e2, fit.top_radius_m, spacing);
      break;
    }
    case ClassShape::kSphere: {
      const int n = std::max(12, static_cast<int>(4 * M_PI * fit.radius_m * fit.radius_m / (spacing * spacing)));
      const double golden = M_PI * (3.0 - std::sqrt(5.0));
      for (int i = 0; i < n; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / n;
        const double rho = std::sqrt(1.0 - z * z);
        out.push_back(fit.center + fit.radius_m * (rho * std::cos(golden * i) * e1 + rho * std::sin(golden * i) * e2 + z * a));
      }
      break;
    }
    case ClassShape::kBox: {
      const Eigen::Vector3d x = fit.x_axis, y = a.cross(x);
      const Eigen::Vector3d half(0.5 * fit.size_m.x(), 0.5 * fit.size_m.y(), h);
      const Eigen::Vector3d axes[3] = {x, y, a};
      for (int face = 0; face < 3; ++face) {
        const int u = (face + 1) % 3, v = (face + 2) % 3;
        const int nu = steps(2 * half(u), spacing), nv = steps(2 * half(v), spacing);
        for (const double sign : {-1.0, 1.0}) {
          for (int i = 0; i <= nu; ++i) {
            for (int j = 0; j <= nv; ++j) {
              out.push_back(fit.center + sign * half(face) * axes[face] + (-half(u) + 2 * half(u) * i / nu) * axes[u] +
                            (-half(v) + 2 * half(v) * j / nv) * axes[v]);
            }
          }
        }
      }
      break;
    }
  }
  return out;
}

}  // namespace scenewatch::ontology
