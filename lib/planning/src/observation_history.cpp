#include "scenewatch/planning/observation_history.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::planning {

namespace {

// Whether one keyframe saw the point: in front, inside its trusted image, depth within tolerance.
bool observed_by(const Eigen::Vector3d& p_world, const background::Keyframe& kf, const DepthAgreement& agreement) {
  const Eigen::Vector3d p = kf.T_world_camera.inverse() * p_world;
  if (!(p.z() > 0.0)) return false;
  const Intrinsics& K = kf.intrinsics;
  const long u = std::lround(K.fx * p.x() / p.z() + K.cx);
  const long v = std::lround(K.fy * p.y() / p.z() + K.cy);
  const long border = agreement.sensor.border_px;
  if (u < border || v < border || u >= kf.depth.width - border || v >= kf.depth.height - border) return false;
  const std::uint16_t mm = kf.depth.depth_mm[static_cast<std::size_t>(v) * kf.depth.width + u];
  if (mm == DepthImage::kInvalid) return false;
  return std::abs(mm * 1e-3 - p.z()) <= agreement.tolerance_m(p.z());
}

}  // namespace

std::vector<std::vector<Eigen::Vector3d>> observing_camera_centres(
    const std::vector<Eigen::Vector3d>& points_world,
    const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes, const DepthAgreement& agreement) {
  std::vector<std::vector<Eigen::Vector3d>> centres(points_world.size());
  for (const auto& kf : keyframes) {
    if (!kf || kf->depth.empty()) continue;
    for (std::size_t i = 0; i < points_world.size(); ++i) {
      if (observed_by(points_world[i], *kf, agreement)) centres[i].push_back(kf->T_world_camera.translation());
    }
  }
  return centres;
}

std::vector<Eigen::Vector3d> box_surface_samples(const OrientedBox& box, const Eigen::Vector3d& up, double spacing_m) {
  const Eigen::Matrix3d R = box.rotation.toRotationMatrix();
  // The face the box rests on: its outward normal points most against up.
  int rest_axis = 0;
  double rest_sign = 1.0, most_down = 1.0;
  for (int a = 0; a < 3; ++a) {
    for (double s : {-1.0, 1.0}) {
      const double d = s * R.col(a).dot(up);
      if (d < most_down) most_down = d, rest_axis = a, rest_sign = s;
    }
  }
  std::vector<Eigen::Vector3d> samples;
  const Eigen::Vector3d half = 0.5 * box.extents;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const int nb = std::max(1, static_cast<int>(std::ceil(box.extents(b) / spacing_m)));
    const int nc = std::max(1, static_cast<int>(std::ceil(box.extents(c) / spacing_m)));
    for (double s : {-1.0, 1.0}) {
      if (a == rest_axis && s == rest_sign) continue;
      for (int i = 0; i < nb; ++i) {
        for (int j = 0; j < nc; ++j) {
          Eigen::Vector3d q;  // cell centres of the face's grid, box frame
          q(a) = s * half(a);
          q(b) = -half(b) + (i + 0.5) * box.extents(b) / nb;
          q(c) = -half(c) + (j + 0.5) * box.extents(c) / nc;
          samples.push_back(box.center + R * q);
        }
      }
    }
  }
  return samples;
}

}  // namespace scenewatch::planning
