#include "scenewatch/core/surface_incidence.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scenewatch/core/depth_validity.h"

namespace scenewatch {

int incidence_window_px(const SensorModel& sensor, double z_m, double focal_px, double sigma_factor) {
  const double noise_px = sigma_factor * sensor.sigma_z(z_m) * focal_px / std::max(z_m, 0.1);
  return std::clamp(static_cast<int>(std::ceil(noise_px)), 2, 8);
}

double surface_incidence_rad(const std::vector<float>& z_m, const Intrinsics& K, int u, int v,
                             const SensorModel& sensor, double sigma_factor) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (u < 0 || v < 0 || u >= K.width || v >= K.height) return kNaN;
  const float zc = z_m[static_cast<std::size_t>(v) * K.width + u];
  if (!(zc > 0)) return kNaN;
  const double f = std::min(K.fx, K.fy);
  const int r = incidence_window_px(sensor, zc, f, sigma_factor);
  const double step = depth_edge_step_m(sensor, zc, f, sigma_factor);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int n = 0;
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du) {
      const int x = u + du, y = v + dv;
      if (x < 0 || y < 0 || x >= K.width || y >= K.height) continue;
      const float z = z_m[static_cast<std::size_t>(y) * K.width + x];
      if (!(z > 0) || std::abs(z - zc) > step * std::max(std::abs(du), std::abs(dv))) continue;
      const Eigen::Vector3d p((x - K.cx) * z / K.fx, (y - K.cy) * z / K.fy, z);
      sum += p;
      outer += p * p.transpose();
      ++n;
    }
  if (n < 6) return kNaN;
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  const Eigen::Vector3d ray = Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0).normalized();
  return std::acos(std::min(1.0, std::abs(normal.dot(ray))));
}

}  // namespace scenewatch
