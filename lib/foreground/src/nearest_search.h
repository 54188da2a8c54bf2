#pragma once
/// Exact nearest neighbours in a frame's target points for the registration: FLANN's k-d tree
/// (the same single-index tree, leaves of 15, as pcl::KdTreeFLANN) searched one query at a time
/// with findNeighbors. pcl::KdTreeFLANN goes through FLANN's knnSearch, which opens an OpenMP
/// parallel region and allocates per query: on hrt1 more than half of the search's time was
/// that (perf: futex wakes, malloc), not the tree. A pcl::search::KdTree, so that PCL's ICP uses
/// it for its correspondences. Private to the foreground module. NOT thread safe (one per call).
#include <memory>

#include <pcl/search/kdtree.h>

#include "scenewatch/core/cloud.h"

namespace scenewatch::foreground {

class NearestSearch : public pcl::search::KdTree<PointT> {
 public:
  NearestSearch();
  ~NearestSearch() override;
  /// Builds the tree over the cloud's x y z (indices are not supported: the whole cloud).
  void setInputCloud(const PointCloudConstPtr& cloud, const IndicesConstPtr& indices = IndicesConstPtr()) override;
  int nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances) const override;
  using pcl::search::KdTree<PointT>::nearestKSearch;

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

}  // namespace scenewatch::foreground
