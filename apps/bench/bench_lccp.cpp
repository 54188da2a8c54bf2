// PCL's supervoxels + LCCP (Stein et al., "Object Partitioning using Local Convexity", CVPR 2014)
// on the points above scenewatch's table, run the way PCL's example runs it
// (pcl/examples/segmentation/example_lccp_segmentation.cpp with -ec -sc, the switches its
// documentation recommends):
//   supervoxels: voxel 0.0075, seed 0.03, colour importance 0, spatial 1, normal 4, no refinement,
//                normals computed by SupervoxelClustering (the mOSD files carry none);
//   LCCP:        concavity tolerance 10 deg, smoothness check on with threshold 0.1 (of the voxel
//                resolution), extended convexity (k = 1), sanity criterion on, no small-segment
//                merging (min segment size 0; small segments are dropped afterwards, as for the
//                other methods, at cfg.min_cluster_points input points).
// The points are in the Kinect's camera frame, camera at the origin looking along +z, so the single
// camera transform (x/z, y/z, ln z: the example's -tvoxel; PCL's own default for organized
// clouds) applies. Our input is the unorganized subset above the table, for which PCL would not
// switch it on by itself, so it is set explicitly. At the mOSD range (~1 m) a 0.0075 bin in
// transformed space is about 7.5 mm.
#include "bench_lccp.h"

#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <map>

namespace scenewatch::bench {
namespace {

constexpr float kVoxelResolution = 0.0075f;
constexpr float kSeedResolution = 0.03f;
constexpr float kColorImportance = 0.0f;
constexpr float kSpatialImportance = 1.0f;
constexpr float kNormalImportance = 4.0f;
constexpr bool kUseSingleCameraTransform = true;
constexpr float kConcavityToleranceDeg = 10.0f;
constexpr float kSmoothnessThreshold = 0.1f;
constexpr std::uint32_t kKFactor = 1;  // extended convexity
constexpr bool kSanityCriterion = true;

// Inside the prism over a convex hull that is counter-clockwise about `normal`: on the inner side
// of every edge. Moving p along the normal does not change the sign, so p need not be projected.
bool above_hull(const Plane& plane, const Eigen::Vector3d& p) {
  const auto& h = plane.hull;
  if (h.size() < 3) return false;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector3d edge = h[(i + 1) % h.size()] - h[i];
    if (plane.normal.dot(edge.cross(p - h[i])) < 0) return false;
  }
  return true;
}

}  // namespace

std::vector<std::vector<int>> lccp_above_table(const Cloud& cloud, const Plane& table, const segmentation::Config& cfg) {
  // The points standing on the table: in the height band, inside the hull, not table inliers.
  std::vector<char> on_table(cloud.size(), 0);
  for (int i : table.indices) on_table[i] = 1;
  auto above = std::make_shared<Cloud>();
  std::vector<int> above_to_input;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& pt = cloud.points[i];
    if (on_table[i] || !is_valid(pt)) continue;
    const Eigen::Vector3d p(pt.x, pt.y, pt.z);
    const double h = table.signed_distance(p);
    if (h < cfg.min_object_height_m || h > cfg.max_object_height_m || !above_hull(table, p)) continue;
    above->push_back(pt);
    above_to_input.push_back(static_cast<int>(i));
  }
  if (above->empty()) return {};

  pcl::SupervoxelClustering<PointT> super(kVoxelResolution, kSeedResolution);
  super.setUseSingleCameraTransform(kUseSingleCameraTransform);
  super.setInputCloud(above);
  super.setColorImportance(kColorImportance);
  super.setSpatialImportance(kSpatialImportance);
  super.setNormalImportance(kNormalImportance);
  std::map<std::uint32_t, pcl::Supervoxel<PointT>::Ptr> supervoxels;
  super.extract(supervoxels);
  if (supervoxels.empty()) return {};
  std::multimap<std::uint32_t, std::uint32_t> adjacency;
  super.getSupervoxelAdjacency(adjacency);

  pcl::LCCPSegmentation<PointT> lccp;
  lccp.setConcavityToleranceThreshold(kConcavityToleranceDeg);
  lccp.setSanityCheck(kSanityCriterion);
  lccp.setSmoothnessCheck(true, kVoxelResolution, kSeedResolution, kSmoothnessThreshold);
  lccp.setKFactor(kKFactor);
  lccp.setInputSupervoxels(supervoxels, adjacency);
  lccp.setMinSegmentSize(0);
  lccp.segment();

  // Supervoxel label per input point (0 = in no supervoxel), then LCCP's segment label.
  const pcl::PointCloud<pcl::PointXYZL>::Ptr labeled = super.getLabeledCloud();
  lccp.relabelCloud(*labeled);
  std::map<std::uint32_t, std::vector<int>> segments;
  for (std::size_t i = 0; i < labeled->size(); ++i) {
    const std::uint32_t label = labeled->points[i].label;
    if (label != 0) segments[label].push_back(above_to_input[i]);
  }
  std::vector<std::vector<int>> out;
  for (auto& [label, indices] : segments)
    if (static_cast<int>(indices.size()) >= cfg.min_cluster_points) out.push_back(std::move(indices));
  return out;
}

}  // namespace scenewatch::bench
