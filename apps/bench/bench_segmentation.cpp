// Planes + clusters on the 45 mOSD Kinect frames (640x480): scenewatch's tabletop segmentation
// against two PCL baselines, in the same run and scored on the same ground truth (strict, point IoU
// >= 0.5 against whole labelled objects, recall and precision, per mOSD category):
//  - a plain PCL pipeline (VoxelGrid + SACSegmentation + EuclideanClusterExtraction) with the same
//    voxel size, RANSAC threshold and cluster tolerance;
//  - PCL's supervoxels + LCCP (bench_lccp.cpp) on the points above scenewatch's table, the
//    model-free baseline that can split touching objects at concave edges.
#include <pcl/ModelCoefficients.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "bench.h"
#include "bench_lccp.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/segmentation/label_scoring.h"
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

// The table from scenewatch (LCCP finds no planes), the objects from supervoxels + LCCP. The time
// of the LCCP part alone goes to `lccp_ms`.
Output lccp_pipeline(const CloudConstPtr& cloud, const segmentation::Config& cfg, double& lccp_ms) {
  const segmentation::Segmentation seg = segmentation::segment(*cloud, cfg);
  Output out;
  lccp_ms = 0.0;
  if (seg.planes.empty()) return out;
  out.plane = seg.planes[0].indices;
  lccp_ms = time_ms([&] { out.clusters = lccp_above_table(*cloud, seg.planes[0], cfg); });
  return out;
}

// Objects and clusters of one method over a set of scenes.
struct Tally {
  std::size_t objects = 0, matched = 0, clusters = 0, correct = 0, tables = 0;
  void add(const segmentation::LabelScore& s) {
    objects += s.objects.size();
    matched += s.matched();
    clusters += s.cluster_best_iou.size();
    correct += s.correct_clusters();
    tables += s.table_iou >= 0.8;
  }
};

// mOSD learn categories: 0-16 boxes, 17-24 stacked boxes, 25-32 occluded, 33-44 cylindric.
constexpr int kCategories = 4;
int category(int scene) { return scene <= 16 ? 0 : scene <= 24 ? 1 : scene <= 32 ? 2 : 3; }

}  // namespace

int run_segmentation(const Options& o) {
  const segmentation::Config cfg;
  enum { kPcl, kLccp, kOurs, kMethods };
  const char* names[kMethods] = {"PCL VoxelGrid + SACSegmentation + Euclidean (baseline)",
                                 "PCL supervoxels + LCCP, on scenewatch's table (baseline)",
                                 "scenewatch segmentation::segment"};
  std::vector<double> ms[kMethods], lccp_only_ms;
  Tally all[kMethods], by_category[kMethods][kCategories];
  std::size_t scenes = 0;
  for (int i = 0; i <= 44; ++i) {
    const auto path = o.data_dir / "mosd/learn" / ("learn" + std::to_string(i) + ".pcd");
    auto file = io::read_cloud(path);
    auto labels = io::read_pcd_labels(path);
    if (!file || !labels) {
      std::fprintf(stderr, "segmentation: %s\n", (file ? labels.error() : file.error()).message.c_str());
      return 1;
    }
    const CloudConstPtr cloud = file->cloud;
    Output out[kMethods];
    for (int r = 0; r < o.repetitions; ++r) {
      ms[kOurs].push_back(time_ms([&] { out[kOurs] = scenewatch_pipeline(cloud, cfg); }));
      ms[kPcl].push_back(time_ms([&] { out[kPcl] = pcl_pipeline(cloud, cfg); }));
      double lccp_ms = 0.0;
      ms[kLccp].push_back(time_ms([&] { out[kLccp] = lccp_pipeline(cloud, cfg, lccp_ms); }));
      lccp_only_ms.push_back(lccp_ms);
    }
    for (int m = 0; m < kMethods; ++m) {
      const auto score = segmentation::score_against_labels(out[m].clusters, out[m].plane, *labels);
      all[m].add(score);
      by_category[m][category(i)].add(score);
    }
    ++scenes;
  }
  std::printf("\n== Planes + clusters: mOSD learn0-44 (%zu Kinect frames, 640x480), %d runs each, voxel %.0f cm\n", scenes,
              o.repetitions, cfg.voxel_size_m * 100);
  std::printf("%-57s %9s %9s %9s %9s %12s %14s %10s\n", "method", "median ms", "p90 ms", "ratio", "vs LCCP", "table found",
              "object recall", "precision");
  const double base = median(ms[kPcl]), lccp = median(ms[kLccp]);
  for (int m = 0; m < kMethods; ++m) {
    const double t = median(ms[m]);
    char ratio[16], vs_lccp[16];
    if (m == kPcl) std::snprintf(ratio, sizeof ratio, "1.00");
    else std::snprintf(ratio, sizeof ratio, "%.2fx", base / t);
    if (m == kLccp) std::snprintf(vs_lccp, sizeof vs_lccp, "1.00");
    else std::snprintf(vs_lccp, sizeof vs_lccp, "%.2fx", lccp / t);
    std::printf("%-57s %9.1f %9.1f %9s %9s %7zu/%-4zu %8zu/%-5zu %4zu/%zu\n", names[m], t, quantile(ms[m], 0.9), ratio, vs_lccp,
                all[m].tables, scenes, all[m].matched, all[m].objects, all[m].correct, all[m].clusters);
  }
  std::printf("%-32s  %-15s  %-15s  %-15s  %-15s  %s\n", "recall  precision, by category", "boxes 0-16", "stacked 17-24",
              "occluded 25-32", "cylindric 33-44", "all");
  for (int m = 0; m < kMethods; ++m) {
    std::printf("%-32s", m == kPcl ? "PCL Euclidean" : m == kLccp ? "PCL supervoxels + LCCP" : "scenewatch");
    for (int c = 0; c < kCategories; ++c) {
      const Tally& t = by_category[m][c];
      char cell[32];
      std::snprintf(cell, sizeof cell, "%zu/%zu  %zu/%zu", t.matched, t.objects, t.correct, t.clusters);
      std::printf("  %-15s", cell);
    }
    std::printf("  %.3f  %.3f\n", static_cast<double>(all[m].matched) / all[m].objects,
                all[m].clusters ? static_cast<double>(all[m].correct) / all[m].clusters : 1.0);
  }
  std::printf("(table found = IoU >= 0.8 with label 1; object recall = labelled objects matched by a cluster at point IoU >= 0.5;\n"
              " precision = clusters that match a labelled object so; ratio = baseline time / method time. LCCP runs on the\n"
              " points 1-50 cm above scenewatch's table inside its hull; its time includes finding the table, supervoxels +\n"
              " LCCP alone take %.1f ms median, p90 %.1f)\n",
              median(lccp_only_ms), quantile(lccp_only_ms, 0.9));
  return 0;
}

}  // namespace scenewatch::bench
