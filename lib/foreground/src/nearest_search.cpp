// FLANN's single-index k-d tree, searched without its per-call OpenMP region.
#include "nearest_search.h"

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>

namespace scenewatch::foreground {

struct NearestSearch::Index {
  std::vector<float> xyz;  // the tree searches these (rows of 3)
  std::unique_ptr<flann::KDTreeSingleIndex<flann::L2_Simple<float>>> tree;
  flann::SearchParams params{-1, 0.0f, true};  // exact
};

NearestSearch::NearestSearch() : index_(std::make_unique<Index>()) {}
NearestSearch::~NearestSearch() = default;

void NearestSearch::setInputCloud(const PointCloudConstPtr& cloud, const IndicesConstPtr&) {
  input_ = cloud;
  index_->xyz.clear();
  index_->xyz.reserve(cloud->size() * 3);
  for (const auto& p : cloud->points) index_->xyz.insert(index_->xyz.end(), {p.x, p.y, p.z});
  index_->tree.reset();
  if (cloud->empty()) return;
  const flann::Matrix<float> data(index_->xyz.data(), cloud->size(), 3);
  index_->tree = std::make_unique<flann::KDTreeSingleIndex<flann::L2_Simple<float>>>(data, flann::KDTreeSingleIndexParams(15));
  index_->tree->buildIndex();
}

int NearestSearch::nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (!index_->tree || k < 1) return 0;
  const float query[3] = {point.x, point.y, point.z};
  flann::KNNSimpleResultSet<float> result(static_cast<std::size_t>(k));
  index_->tree->findNeighbors(result, query, index_->params);
  const std::size_t n = std::min(result.size(), static_cast<std::size_t>(k));
  std::vector<std::size_t> found(n);
  k_sqr_distances.resize(n);
  result.copy(found.data(), k_sqr_distances.data(), n, true);
  k_indices.assign(found.begin(), found.end());
  return static_cast<int>(n);
}

}  // namespace scenewatch::foreground
