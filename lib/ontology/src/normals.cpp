// PCL's NormalEstimation rather than CGAL's jet or PCA estimation: PCL ships it precompiled for
// our point type (no template instantiation on the 2-core machine, CGAL stays in one translation
// unit), and it orients normals towards the viewpoint, which a single view knows exactly.
#include "normals.h"

#include <cmath>
#include <limits>

#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>

namespace scenewatch::ontology::detail {

std::vector<Eigen::Vector3d> estimate_normals(const Cloud& cloud, const std::vector<int>& indices, int k,
                                              const Eigen::Vector3d& sensor_origin) {
  // A copy of the object's points: with setIndices on the whole cloud, PCL builds its search tree
  // over every point of the frame (33 ms for VGA) and takes neighbours from other objects.
  auto object = std::make_shared<Cloud>();
  object->points.reserve(indices.size());
  for (const int i : indices) object->points.push_back(cloud.points[static_cast<std::size_t>(i)]);
  object->width = static_cast<std::uint32_t>(object->points.size());
  object->height = 1;
  object->is_dense = true;
  pcl::NormalEstimation<PointT, pcl::Normal> estimation;
  estimation.setInputCloud(object);
  estimation.setSearchMethod(std::make_shared<pcl::search::KdTree<PointT>>());
  estimation.setKSearch(k);
  estimation.setViewPoint(static_cast<float>(sensor_origin.x()), static_cast<float>(sensor_origin.y()),
                          static_cast<float>(sensor_origin.z()));
  pcl::PointCloud<pcl::Normal> normals;
  estimation.compute(normals);

  std::vector<Eigen::Vector3d> out(indices.size(), Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (std::size_t i = 0; i < normals.size() && i < out.size(); ++i) {
    const Eigen::Vector3d n = normals[i].getNormalVector3fMap().cast<double>();
    if (n.allFinite() && n.norm() > 0.5) out[i] = n.normalized();
  }
  return out;
}

}  // namespace scenewatch::ontology::detail
