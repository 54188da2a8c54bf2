// Planes + clusters on the 45 mOSD Kinect frames (640x480): scenescwatch's tabletop segmentation
// against a plain PCL pipeline (VoxelGrid + SACSegmentation + EuclideanClusterExtraction) with
// the same voxel size, RANSAC threshold and cluster tolerance. Both are scored on the same
// ground truth: object recall at point IoU >= 0.5 in the input cloud.
#include <pcl/ModelCoefficients.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "bench.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/segmentation/evaluation.h"
#include "scenewatch/segmentation/tabletop.h"

namespace scenewatch::bench {
namespace {

struct Output {
  std::vector<std::vector<int>> clusters;  // input indices
  std::vector<int> plane;
};

Output pcl_pipeline(const CloudConstPtr& cloud, const segmentation::Config& cfg) {
  Output out;
  pcl::VoxelGrid<PointT> grid;
  auto down = std::make_shared<Cloud>();
  grid.setInputCloud(cloud);
  const float leaf = static_cast<float>(cfg.voxel_size_m);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setSaveLeafLayout(true);
  grid.filter(*down);

  pcl::SACSegmentation<PointT> sac;
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(cfg.plane_distance_m);
  sac.setMaxIterations(cfg.ransac_iterations);
  sac.setOptimizeCoefficients(true);
  sac.setInputCloud(down);
  auto inliers = std::make_shared<pcl::PointIndices>();
  pcl::ModelCoefficients coefficients;
  sac.segment(*inliers, coefficients);

  auto rest = std::make_shared<Cloud>();
  std::vector<int> rest_to_down;
  std::vector<char> is_plane(down->size(), 0);
  for (int i : inliers->indices) is_plane[i] = 1;
  for (std::size_t i = 0; i < down->size(); ++i) {
    if (!is_plane[i]) {
      rest->push_back(down->points[i]);
      rest_to_down.push_back(static_cast<int>(i));
    }
  }
  std::vector<pcl::PointIndices> clusters;
  if (!rest->empty()) {
    auto tree = std::make_shared<pcl::search::KdTree<PointT>>();
    pcl::EuclideanClusterExtraction<PointT> ec;
    ec.setClusterTolerance(cfg.cluster_tolerance_m);
    ec.setMinClusterSize(10);
    ec.setMaxClusterSize(1000000);
    ec.setSearchMethod(tree);
    ec.setInputCloud(rest);
    ec.extract(clusters);
  }
  // Back to input indices through the voxel layout.
  std::vector<int> down_cluster(down->size(), -1);
  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (int i : clusters[c].indices) down_cluster[rest_to_down[i]] = static_cast<int>(c);
  out.clusters.resize(clusters.size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const PointT& p = cloud->points[i];
    if (!is_valid(p)) continue;
    const int v = grid.getCentroidIndexAt(grid.getGridCoordinates(p.x, p.y, p.z));
    if (v < 0) continue;
    if (is_plane[v]) out.plane.push_back(static_cast<int>(i));
    else if (down_cluster[v] >= 0) out.clusters[down_cluster[v]].push_back(static_cast<int>(i));
  }
  // Same minimum object size as scenewatch, in input points.
  out.clusters.erase(std::remove_if(out.clusters.begin(), out.clusters.end(),
                                    [&](const std::vector<int>& c) { return static_cast<int>(c.size()) < cfg.min_cluster_points; }),
                     out.clusters.end());
  return out;
}

Output scenewatch_pipeline(const CloudConstPtr& cloud, const segmentation::Config& cfg) {
  const segmentation::Segmentation seg = segmentation::segment(*cloud, cfg);
  Output out;
  for (const auto& o : seg.objects) out.clusters.push_back(o.indices);
  if (!seg.planes.empty()) out.plane = seg.planes[0].indices;
  return out;
}

}  // namespace

int run_segmentation(const Options& o) {
  const segmentation::Config cfg;
  std::vector<double> ours_ms, pcl_ms;
  std::size_t objects = 0, ours_matched = 0, pcl_matched = 0, ours_tables = 0, pcl_tables = 0, scenes = 0;
  for (int i = 0; i <= 44; ++i) {
    const auto path = o.data_dir / "mosd/learn" / ("learn" + std::to_string(i) + ".pcd");
    auto file = io::read_cloud(path);
    auto labels = io::read_pcd_labels(path);
    if (!file || !labels) {
      std::fprintf(stderr, "segmentation: %s\n", (file ? labels.error() : file.error()).message.c_str());
      return 1;
    }
    const CloudConstPtr cloud = file->cloud;
    Output ours, base;
    for (int r = 0; r < o.repetitions; ++r) {
      ours_ms.push_back(time_ms([&] { ours = scenewatch_pipeline(cloud, cfg); }));
      pcl_ms.push_back(time_ms([&] { base = pcl_pipeline(cloud, cfg); }));
    }
    const auto s_ours = segmentation::score_against_labels(ours.clusters, ours.plane, *labels);
    const auto s_pcl = segmentation::score_against_labels(base.clusters, base.plane, *labels);
    objects += s_ours.objects.size();
    ours_matched += s_ours.matched();
    pcl_matched += s_pcl.matched();
    ours_tables += s_ours.table_iou >= 0.8;
    pcl_tables += s_pcl.table_iou >= 0.8;
    ++scenes;
  }
  std::printf("\n== Planes + clusters: mOSD learn0-44 (%zu Kinect frames, 640x480), %d runs each, voxel %.0f cm\n", scenes,
              o.repetitions, cfg.voxel_size_m * 100);
  std::printf("%-52s %10s %10s %10s %14s %14s\n", "method", "median ms", "p90 ms", "ratio", "table found", "object recall");
  const double base = median(pcl_ms);
  std::printf("%-52s %10.1f %10.1f %10s %9zu/%-4zu %8zu/%zu\n", "PCL VoxelGrid + SACSegmentation + Euclidean (baseline)", base,
              quantile(pcl_ms, 0.9), "1.00", pcl_tables, scenes, pcl_matched, objects);
  std::printf("%-52s %10.1f %10.1f %9.2fx %9zu/%-4zu %8zu/%zu\n", "scenewatch segmentation::segment", median(ours_ms),
              quantile(ours_ms, 0.9), base / median(ours_ms), ours_tables, scenes, ours_matched, objects);
  std::printf("(table found = IoU >= 0.8 with label 1; object recall = labelled objects matched by a cluster at point IoU >= 0.5)\n");
  return 0;
}

}  // namespace scenewatch::bench
