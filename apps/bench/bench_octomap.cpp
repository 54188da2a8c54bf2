// OctoMap insertion of one real VGA frame: scenewatch's batched insertion against OctoMap's plain
// OcTree::insertPointCloud (and its discretized variant), into an empty map, at 1 and 2 cm.
#include <octomap/OcTree.h>

#include <set>
#include <tuple>

#include "bench.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::bench {

namespace {

struct Case {
  std::string name;
  CloudConstPtr cloud;
  Pose T_world_camera = Pose::Identity();
  CloudConstPtr next_cloud;  // the following frame, for inserting into an existing map
  Pose next_T = Pose::Identity();
};

octomap::Pointcloud to_scan(const Cloud& cloud, const Pose& T) {
  octomap::Pointcloud scan;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (const auto& p : cloud.points) {
    if (!is_valid(p)) continue;
    const Eigen::Vector3f w = Tf * p.getVector3fMap();
    scan.push_back(w.x(), w.y(), w.z());
  }
  return scan;
}

std::set<std::tuple<long, long, long>> occupied_keys(const std::vector<Eigen::Vector3d>& centers, double res) {
  std::set<std::tuple<long, long, long>> s;
  for (const auto& c : centers) s.emplace(std::lround(std::floor(c.x() / res)), std::lround(std::floor(c.y() / res)), std::lround(std::floor(c.z() / res)));
  return s;
}

std::vector<Eigen::Vector3d> occupied_centers(const octomap::OcTree& tree, double res) {
  std::vector<Eigen::Vector3d> centers;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::lround(size / res)));
    const auto c = it.getCoordinate();
    for (int x = 0; x < n; ++x)
      for (int y = 0; y < n; ++y)
        for (int z = 0; z < n; ++z)
          centers.emplace_back(c.x() - size / 2 + (x + 0.5) * res, c.y() - size / 2 + (y + 0.5) * res, c.z() - size / 2 + (z + 0.5) * res);
  }
  return centers;
}

void run_case(const Case& c, const Options& o) {
  const octomap::Pointcloud scan = to_scan(*c.cloud, c.T_world_camera);
  const octomap::Pointcloud next_scan = to_scan(*c.next_cloud, c.next_T);
  const auto& t = c.T_world_camera.translation();
  const auto& tn = c.next_T.translation();
  const octomap::point3d origin(t.x(), t.y(), t.z()), next_origin(tn.x(), tn.y(), tn.z());
  std::printf("\n-- %s: %zu valid points\n", c.name.c_str(), scan.size());
  std::printf("%-6s %-38s %12s %8s %14s %8s %10s\n", "res", "method", "empty map ms", "ratio", "next frame ms", "ratio",
              "agreement");
  for (double res : {0.02, 0.01}) {
    std::vector<double> plain_ms, plain_next, disc_ms, disc_next, fast_ms, fast_next;
    std::set<std::tuple<long, long, long>> plain_set;
    for (int r = 0; r < o.repetitions; ++r) {
      octomap::OcTree tree(res);
      plain_ms.push_back(time_ms([&] { tree.insertPointCloud(scan, origin, 5.0, false, false); }));
      plain_next.push_back(time_ms([&] { tree.insertPointCloud(next_scan, next_origin, 5.0, false, false); }));
      if (r == 0) plain_set = occupied_keys(occupied_centers(tree, res), res);
      octomap::OcTree disc(res);
      disc_ms.push_back(time_ms([&] { disc.insertPointCloud(scan, origin, 5.0, false, true); }));
      disc_next.push_back(time_ms([&] { disc.insertPointCloud(next_scan, next_origin, 5.0, false, true); }));
    }
    std::size_t fast_occupied = 0, common = 0;
    for (int r = 0; r < o.repetitions; ++r) {
      background::Config cfg;
      cfg.resolution_m = res;
      background::OccupancyMap map(cfg);
      fast_ms.push_back(time_ms([&] { map.insert(*c.cloud, c.T_world_camera); }));
      fast_next.push_back(time_ms([&] { map.insert(*c.next_cloud, c.next_T); }));
      if (r == 0) {
        const auto s = occupied_keys(map.occupied_voxel_centers(), res);
        fast_occupied = s.size();
        for (const auto& k : s) common += plain_set.count(k);
      }
    }
    const double base = median(plain_ms), base_next = median(plain_next);
    const double jaccard = static_cast<double>(common) / (fast_occupied + plain_set.size() - common);
    std::printf("%-6s %-38s %12.1f %8s %14.1f %8s %10s\n", res == 0.02 ? "2 cm" : "1 cm", "OcTree::insertPointCloud (baseline)",
                base, "1.00", base_next, "1.00", "-");
    std::printf("%-6s %-38s %12.1f %7.2fx %14.1f %7.2fx %10s\n", "", "OcTree::insertPointCloud, discretize", median(disc_ms),
                base / median(disc_ms), median(disc_next), base_next / median(disc_next), "");
    std::printf("%-6s %-38s %12.1f %7.2fx %14.1f %7.2fx %9.2f%%\n", "", "scenewatch OccupancyMap::insert", median(fast_ms),
                base / median(fast_ms), median(fast_next), base_next / median(fast_next), 100.0 * jaccard);
  }
}

}  // namespace

int run_octomap(const Options& o) {
  std::printf("\n== OctoMap insertion of one VGA frame, max range 5 m, median of %d runs\n", o.repetitions);
  std::vector<Case> cases;
  {
    auto seq = io::open_sequence(o.data_dir / "redkitchen");
    if (!seq) {
      std::fprintf(stderr, "octomap: %s\n", seq.error().message.c_str());
      return 1;
    }
    auto a = io::load_sequence_frame(*seq, 0), b = io::load_sequence_frame(*seq, 1);
    if (!a || !b) {
      std::fprintf(stderr, "octomap: %s\n", (a ? b.error() : a.error()).message.c_str());
      return 1;
    }
    cases.push_back({"redkitchen frame-000150 (7-Scenes room, depth up to 4 m), then frame-000151", a->cloud,
                     *a->T_world_camera, b->cloud, *b->T_world_camera});
  }
  {
    auto a = io::read_cloud(o.data_dir / "mosd/learn/learn33.pcd"), b = io::read_cloud(o.data_dir / "mosd/learn/learn34.pcd");
    if (!a || !b) {
      std::fprintf(stderr, "octomap: %s\n", (a ? b.error() : a.error()).message.c_str());
      return 1;
    }
    cases.push_back({"mOSD learn33 (Kinect tabletop, ~1 m), then learn34 (same camera)", a->cloud, Pose::Identity(), b->cloud,
                     Pose::Identity()});
  }
  for (const auto& c : cases) run_case(c, o);
  std::printf("(ratio = baseline time / method time; agreement = Jaccard of the occupied voxels with the baseline after\n"
              " the first frame; scenewatch's map is a ColorOcTree and also averages colour per voxel)\n");
  return 0;
}

}  // namespace scenewatch::bench
