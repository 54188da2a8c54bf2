// Growing a foreground object's point model from its registered views.
#include "point_model.h"

#include "skin_model.h"
#include "scenewatch/core/voxel_set.h"

namespace scenewatch::foreground {

bool worth_merging(const Registration& r, const ModelGrowth& growth) {
  return r.ok && r.rmse_m <= growth.max_rmse_m && r.inlier_fraction >= growth.min_inlier_fraction;
}

namespace {

// The view's points that are not skin (a hand the detector left out, fingers over the object).
std::vector<int> without_skin(const Cloud& cloud, const std::vector<int>& view) {
  const auto skin = skin_mask(cloud, view);
  std::vector<int> out;
  out.reserve(view.size());
  for (std::size_t k = 0; k < view.size(); ++k)
    if (!skin[k]) out.push_back(view[k]);
  return out;
}

}  // namespace

CloudPtr merged(const CloudPtr& model, const Cloud& cloud, const std::vector<int>& view,
                     const Pose& T_object_camera, const ModelGrowth& growth) {
  if (model->size() >= growth.max_points || view.empty()) return model;
  VoxelSet held(growth.voxel_m);
  for (const auto& p : model->points) held.insert(p.getVector3fMap().cast<double>());
  auto out = std::make_shared<Cloud>(*model);
  const Eigen::Matrix3f R = T_object_camera.linear().cast<float>();
  const Eigen::Vector3f t = T_object_camera.translation().cast<float>();
  for (int i : without_skin(cloud, view)) {
    PointT q = cloud.points[static_cast<std::size_t>(i)];
    if (!is_valid(q)) continue;
    q.getVector3fMap() = R * q.getVector3fMap() + t;
    if (!held.insert(q.getVector3fMap().cast<double>())) continue;
    out->push_back(q);
    if (out->size() >= growth.max_points) break;
  }
  if (out->size() == model->size()) return model;
  out->width = static_cast<std::uint32_t>(out->size());
  out->height = 1;
  return out;
}

}  // namespace scenewatch::foreground
