#include "scenewatch/segmentation/label_scoring.h"

#include <algorithm>
#include <map>
#include <random>

namespace scenewatch::segmentation {

std::size_t LabelScore::matched(double t) const {
  return static_cast<std::size_t>(std::count_if(objects.begin(), objects.end(), [t](const ObjectScore& o) { return o.best_iou >= t; }));
}

double LabelScore::recall(double t) const { return objects.empty() ? 1.0 : static_cast<double>(matched(t)) / objects.size(); }

std::size_t LabelScore::correct_clusters(double t) const {
  return static_cast<std::size_t>(std::count_if(cluster_best_iou.begin(), cluster_best_iou.end(), [t](double v) { return v >= t; }));
}

double LabelScore::precision(double t) const {
  return cluster_best_iou.empty() ? 1.0 : static_cast<double>(correct_clusters(t)) / cluster_best_iou.size();
}

LabelScore score_against_labels(const std::vector<std::vector<int>>& clusters, const std::vector<int>& plane_indices,
                                const std::vector<std::uint32_t>& labels, std::uint32_t table_label, std::uint32_t divisor,
                                std::size_t min_object_points) {
  LabelScore score;
  // Ground-truth object of each point (0 = none).
  std::map<std::uint32_t, std::size_t> gt_size;
  std::size_t table_points = 0;
  for (std::uint32_t l : labels) {
    if (l == table_label) ++table_points;
    if (l >= divisor) ++gt_size[l / divisor];
  }
  std::size_t table_hits = 0;
  for (int i : plane_indices) table_hits += labels[i] == table_label ? 1 : 0;
  const std::size_t table_union = table_points + plane_indices.size() - table_hits;
  score.table_iou = table_union ? static_cast<double>(table_hits) / table_union : 0.0;

  score.cluster_best_iou.assign(clusters.size(), 0.0);
  for (const auto& [id, n] : gt_size) {
    ObjectScore o;
    o.object_id = id;
    o.points = n;
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      std::size_t inter = 0;
      for (int i : clusters[c]) inter += (labels[i] >= divisor && labels[i] / divisor == id) ? 1 : 0;
      const double iou = static_cast<double>(inter) / (n + clusters[c].size() - inter);
      // A cluster matching an object too small to count is not wrong.
      score.cluster_best_iou[c] = std::max(score.cluster_best_iou[c], n < min_object_points && iou >= 0.5 ? 1.0 : iou);
      if (iou > o.best_iou) {
        o.best_iou = iou;
        o.best_cluster = static_cast<int>(c);
      }
    }
    if (n >= min_object_points) score.objects.push_back(o);
  }
  return score;
}

LabelledCloud unorganized_copy(const Cloud& cloud, const std::vector<std::uint32_t>& labels, std::uint32_t seed) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (is_valid(cloud[i])) order.push_back(i);
  std::mt19937 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  LabelledCloud out;
  out.cloud.reserve(order.size());
  out.labels.reserve(order.size());
  for (std::size_t i : order) {
    out.cloud.push_back(cloud[i]);
    out.labels.push_back(labels[i]);
  }
  out.cloud.width = static_cast<std::uint32_t>(out.cloud.size());
  out.cloud.height = 1;
  out.cloud.is_dense = true;
  return out;
}

}  // namespace scenewatch::segmentation
