// Points of objects and clusters (object_points.h), as the foreground tracker had them.
#include "object_points.h"

#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {

Aabb bounds(const std::vector<Eigen::Vector3d>& pts) {
  Aabb box{Eigen::Vector3d::Constant(1e30), Eigen::Vector3d::Constant(-1e30)};
  for (const auto& p : pts) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  return box;
}

CloudPtr thinned(const Cloud& in, double voxel, std::size_t max_points) {
  auto out = std::make_shared<Cloud>();
  if (voxel > 0) {
    VoxelSet seen(voxel);
    for (const auto& p : in.points) {
      if (seen.insert(p.getVector3fMap().cast<double>())) out->push_back(p);
    }
  } else {
    *out = in;
  }
  if (out->size() > max_points) {
    auto every = std::make_shared<Cloud>();
    const double step = static_cast<double>(out->size()) / max_points;
    for (double i = 0; i < out->size() && every->size() < max_points; i += step) every->push_back(out->points[static_cast<std::size_t>(i)]);
    out = every;
  }
  out->width = static_cast<std::uint32_t>(out->size());
  out->height = 1;
  return out;
}

Aabb world_box(const ObjectCluster& c) {
  const Eigen::Matrix3d R = c.box.rotation.toRotationMatrix();
  const Eigen::Vector3d half = (R.cwiseAbs() * c.box.extents) / 2;
  return {c.box.center - half, c.box.center + half};
}

std::vector<Eigen::Vector3d> world_points(const FrameView& f, const ObjectCluster& c) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(c.indices.size());
  for (int i : c.indices) out.push_back(world(f.cloud->points[static_cast<std::size_t>(i)], f.T_world_camera));
  return out;
}

Cloud cluster_cloud(const FrameView& f, const ObjectCluster& c, const Pose& T_frame_world) {
  const Pose T = T_frame_world * f.T_world_camera;
  Cloud out;
  for (int i : c.indices) {
    PointT q = f.cloud->points[static_cast<std::size_t>(i)];
    q.getVector3fMap() = (T * q.getVector3fMap().cast<double>()).cast<float>();
    out.push_back(q);
  }
  out.width = static_cast<std::uint32_t>(out.size());
  out.height = 1;
  return out;
}

Pose object_frame(const ObjectCluster& c, const Eigen::Matrix3d& R) {
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = c.centroid;
  return T;
}

std::vector<Eigen::Vector3d> posed_points(const Cloud& model, const Pose& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(model.size());
  for (const auto& p : model.points) out.push_back(world(p, T));
  return out;
}

}  // namespace scenewatch::foreground
