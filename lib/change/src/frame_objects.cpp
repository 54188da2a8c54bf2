// The segmented objects of a frame by point.
#include "scenewatch/change/frame_objects.h"

namespace scenewatch::change {

ObjectLabels label_objects(const segmentation::Segmentation& segmentation, std::size_t cloud_size) {
  ObjectLabels labels;
  labels.object_of.assign(cloud_size, -1);
  for (const auto& object : segmentation.objects) {
    const int id = static_cast<int>(labels.members.size());
    for (int i : object.indices) labels.object_of[i] = id;
    labels.members.push_back(object.indices);
  }
  return labels;
}

ObjectLabels segment_objects(const Cloud& cloud, const segmentation::Config& config, int stride) {
  return label_objects(segmentation::segment_strided(cloud, config, Eigen::Vector3d::Zero(), stride), cloud.size());
}

}  // namespace scenewatch::change
