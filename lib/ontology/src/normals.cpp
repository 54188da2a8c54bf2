// Normals by PCA of k nearest neighbours. The kd-tree version is PCL's NormalEstimation (precompiled
// for our point type, orients normals towards the viewpoint, which a single view knows exactly).
// The default finds the neighbours in a hash grid instead: on objects of about 5000 points, PCL's
// k-NN queries (FLANN) took most of the fit's time.
#include "normals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>

namespace scenewatch::ontology::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Rings of cells searched around a point before it is compared with every point.
constexpr int kMaxRings = 4;

/// A cell's key: 21 bits per coordinate (cells of a few mm span kilometres).
std::uint64_t cell_key(const Eigen::Vector3i& c) {
  constexpr std::int64_t kOffset = 1 << 20;
  const auto part = [](int v) { return static_cast<std::uint64_t>(static_cast<std::int64_t>(v) + kOffset) & 0x1fffff; };
  return part(c.x()) | (part(c.y()) << 21) | (part(c.z()) << 42);
}

using Candidate = std::pair<float, std::uint32_t>;  // (squared distance, point)

/// Moves the `want` nearest of `c` (all with squared distance <= max_d2) to its front, in any
/// order: a radix select, as std::nth_element's unpredictable branches were the normals' largest
/// cost. Bins of equal squared distance hold about equally many points of a surface patch; one
/// pass counts them, a branchless pass moves the bins before the want-th point's bin to the front,
/// and only that bin's few points are ordered.
void select_nearest(std::vector<Candidate>& c, std::size_t want, float max_d2, std::vector<Candidate>& scratch) {
  constexpr int kBins = 16;
  const float scale = max_d2 > 0 ? kBins / max_d2 : 0.0f;
  const auto bin = [&](float d2) { return std::min(kBins - 1, static_cast<int>(d2 * scale)); };
  std::array<std::uint32_t, kBins> counts{};
  for (const Candidate& x : c) ++counts[static_cast<std::size_t>(bin(x.first))];
  int last = 0;  // the bin of the want-th nearest
  std::size_t before = 0;
  while (before + counts[static_cast<std::size_t>(last)] < want) before += counts[static_cast<std::size_t>(last++)];
  // scratch: the nearer bins' points in [0, before), the want-th's bin's from before + 1; each
  // write lands in its region or, when the point belongs to the other one, in the slot after it.
  const std::size_t in_bin = counts[static_cast<std::size_t>(last)];
  scratch.resize(before + in_bin + 2);
  std::size_t near = 0, same = before + 1;
  for (const Candidate& x : c) {
    const int b = bin(x.first);
    scratch[near] = x;
    near += b < last ? 1 : 0;
    scratch[same] = x;
    same += b == last ? 1 : 0;
  }
  const auto first = scratch.begin() + static_cast<std::ptrdiff_t>(before + 1);
  std::nth_element(first, first + static_cast<std::ptrdiff_t>(want - 1 - before), first + static_cast<std::ptrdiff_t>(in_bin));
  std::copy(scratch.begin(), scratch.begin() + static_cast<std::ptrdiff_t>(before), c.begin());
  std::copy(first, first + static_cast<std::ptrdiff_t>(want - before), c.begin() + static_cast<std::ptrdiff_t>(before));
}

/// Points of a few grid cells in float arrays (one per coordinate), so that the distances to all
/// of them vectorise.
class Block {
 public:
  void clear() {
    x_.clear(), y_.clear(), z_.clear(), id_.clear();
  }
  void add(const Eigen::Vector3d& p, std::uint32_t id) {
    x_.push_back(static_cast<float>(p.x())), y_.push_back(static_cast<float>(p.y())), z_.push_back(static_cast<float>(p.z()));
    id_.push_back(id);
  }
  /// Squared distances from q to the block's points, for within().
  void distances(const Eigen::Vector3d& q) {
    const float qx = static_cast<float>(q.x()), qy = static_cast<float>(q.y()), qz = static_cast<float>(q.z());
    const std::size_t m = x_.size();
    d2_.resize(m);
    for (std::size_t j = 0; j < m; ++j) {
      const float dx = x_[j] - qx, dy = y_[j] - qy, dz = z_[j] - qz;
      d2_[j] = dx * dx + dy * dy + dz * dz;
    }
  }
  /// The block's points within sqrt(max_d2) of the last distances()' point, as (squared distance,
  /// id), into out (cleared).
  void within(float max_d2, std::vector<Candidate>& out) const {
    // Branchless: every point is written, the count moves past those within reach.
    out.resize(d2_.size() + 1);
    std::size_t count = 0;
    for (std::size_t j = 0; j < d2_.size(); ++j) {
      out[count] = Candidate(d2_[j], id_[j]);
      count += d2_[j] <= max_d2 ? 1 : 0;
    }
    out.resize(count);
  }

 private:
  std::vector<float> x_, y_, z_, d2_;
  std::vector<std::uint32_t> id_;
};

/// The 90th percentile over a sample of up to 32 points of the distance to their k-th nearest
/// neighbour (brute force: 32 x n distances): a cell that wide holds the k nearest of 9 in 10
/// points within the 27 cells around them. Only the distances within three times the largest such
/// distance so far are selected from (the k nearest are among them when there are k), the others
/// only when there are fewer; float distances, as the cell sets only the search's speed.
double typical_kth_distance(const std::vector<Eigen::Vector3d>& p, int k) {
  const std::size_t n = p.size();
  const std::size_t step = std::max<std::size_t>(1, n / 32);
  std::vector<Eigen::Vector3f> q(n);
  for (std::size_t j = 0; j < n; ++j) q[j] = p[j].cast<float>();
  std::vector<float> d2(n);
  std::vector<double> kth;
  float bound2 = std::numeric_limits<float>::infinity();
  const auto want = static_cast<std::size_t>(k) + 1;  // the point itself is its own nearest
  for (std::size_t i = 0; i < n; i += step) {
    std::size_t count = 0;
    for (std::size_t j = 0; j < n; ++j) {  // branchless: each written, the count moved past the near
      const float d = (q[j] - q[i]).squaredNorm();
      d2[count] = d;
      count += d <= bound2 ? 1 : 0;
    }
    if (count < want) {
      for (std::size_t j = 0; j < n; ++j) d2[j] = (q[j] - q[i]).squaredNorm();
      count = n;
    }
    std::nth_element(d2.begin(), d2.begin() + k, d2.begin() + static_cast<std::ptrdiff_t>(count));
    const float kth2 = d2[static_cast<std::size_t>(k)];
    kth.push_back(std::sqrt(static_cast<double>(kth2)));
    bound2 = kth.size() == 1 ? 9 * kth2 : std::max(bound2, 9 * kth2);
  }
  const std::size_t at = kth.size() * 9 / 10;
  std::nth_element(kth.begin(), kth.begin() + static_cast<std::ptrdiff_t>(at), kth.end());
  return kth[at];
}

}  // namespace

std::vector<Eigen::Vector3d> estimate_normals(const Cloud& cloud, const std::vector<int>& indices, int k,
                                              const Eigen::Vector3d& sensor_origin) {
  const std::size_t n = indices.size();
  std::vector<Eigen::Vector3d> out(n, Eigen::Vector3d::Constant(kNaN));
  if (k < 3 || n < static_cast<std::size_t>(k) + 1) return out;
  std::vector<Eigen::Vector3d> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = cloud.points[static_cast<std::size_t>(indices[i])].getVector3fMap().cast<double>();

  const double cell = typical_kth_distance(p, k);
  if (!(cell > 0)) return out;  // all points in one spot
  // The grid: points sorted by cell, and each cell's range in that order.
  std::vector<Eigen::Vector3i> cell_of(n);
  std::vector<std::uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    cell_of[i] = (p[i] / cell).array().floor().cast<int>();
    key[i] = cell_key(cell_of[i]);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells;
  cells.reserve(n);
  for (std::uint32_t s = 0; s < n;) {
    std::uint32_t e = s;
    while (e < n && key[order[e]] == key[order[s]]) ++e;
    cells.emplace(key[order[s]], std::make_pair(s, e));
    s = e;
  }

  // Squared distances in float: the points are the cloud's floats, so differences of neighbours
  // are exact and only exact ties could order differently; the covariance stays in double.
  std::vector<Candidate> candidates, scratch;
  candidates.reserve(512);
  Block block;  // the points of the 27 cells around one cell
  const std::size_t want = std::min<std::size_t>(n, static_cast<std::size_t>(k));  // the point and k - 1 others, as PCL counts
  // Finds the k nearest of point i into candidates[0, want) by rings of cells around its cell:
  // after ring r every point within r cells' width is a candidate, so the k nearest are exact once
  // the k-th candidate is that near (an outlier far from all others is compared with every point).
  const auto search_rings = [&](std::size_t i) {
    candidates.clear();
    for (int ring = 1;; ++ring) {
      for (int dx = -ring; dx <= ring; ++dx)
        for (int dy = -ring; dy <= ring; ++dy)
          for (int dz = -ring; dz <= ring; ++dz) {
            if (ring > 1 && std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != ring) continue;  // inner rings done
            const auto found = cells.find(cell_key(cell_of[i] + Eigen::Vector3i(dx, dy, dz)));
            if (found == cells.end()) continue;
            for (std::uint32_t s = found->second.first; s < found->second.second; ++s)
              candidates.emplace_back(static_cast<float>((p[order[s]] - p[i]).squaredNorm()), order[s]);
          }
      if (ring == kMaxRings) {
        candidates.clear();
        for (std::uint32_t j = 0; j < n; ++j) candidates.emplace_back(static_cast<float>((p[j] - p[i]).squaredNorm()), j);
      }
      // Only the candidates within the rings' reach can be the k nearest found so far: selecting
      // among those (a few dozen of several hundred at ring 2) leaves the others for a wider ring.
      const auto reach2 = static_cast<float>(ring * cell * ring * cell);
      const auto end = ring >= kMaxRings ? candidates.end()
                                         : std::partition(candidates.begin(), candidates.end(),
                                                          [&](const auto& c) { return c.first <= reach2; });
      if (static_cast<std::size_t>(end - candidates.begin()) < want) continue;
      std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(want - 1), end);
      return;
    }
  };
  // Cell by cell: the 27 cells around a cell are looked up once for all of its points; a point
  // whose k-th nearest among them lies beyond one cell's width searches further on its own.
  for (const auto& [cell_key_value, range] : cells) {
    (void)cell_key_value;
    const std::size_t first = order[range.first];
    block.clear();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto found = cells.find(cell_key(cell_of[first] + Eigen::Vector3i(dx, dy, dz)));
          if (found == cells.end()) continue;
          for (std::uint32_t s = found->second.first; s < found->second.second; ++s) block.add(p[order[s]], order[s]);
        }
    for (std::uint32_t s = range.first; s < range.second; ++s) {
      const std::size_t i = order[s];
      // The block holds every point within `reach` of p[i]: one cell's width plus p[i]'s distance
      // to the nearest face of its own cell. Only those can be among the k nearest found here:
      // when there are k of them, the k nearest of those are exact; else the rings decide.
      const Eigen::Vector3d offset = p[i] / cell - cell_of[i].cast<double>();  // in [0, 1) per axis
      const double reach = cell * (1.0 + std::min(offset.minCoeff(), 1.0 - offset.maxCoeff()));
      // The ball of one cell's width lies in the block too and, the cell being the typical k-th
      // neighbour distance, usually holds k points: then the selection sorts only its points.
      block.distances(p[i]);
      auto max_d2 = static_cast<float>(cell * cell);
      block.within(max_d2, candidates);
      if (candidates.size() < want) block.within(max_d2 = static_cast<float>(reach * reach), candidates);
      if (candidates.size() >= want) {
        select_nearest(candidates, want, max_d2, scratch);
      } else {
        search_rings(i);
      }
      // The covariance from sums relative to p[i], in one pass.
      const std::size_t count = std::min(candidates.size(), want);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d squares = Eigen::Matrix3d::Zero();
      for (std::size_t j = 0; j < count; ++j) {
        const Eigen::Vector3d d = p[candidates[j].second] - p[i];
        sum += d;
        squares.noalias() += d * d.transpose();
      }
      if (count < 3) continue;
      const Eigen::Matrix3d covariance = squares - sum * sum.transpose() / static_cast<double>(count);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(covariance);
      Eigen::Vector3d normal = solver.eigenvectors().col(0);  // smallest eigenvalue first
      if (!normal.allFinite() || normal.norm() < 0.5) continue;
      normal.normalize();
      if (normal.dot(sensor_origin - p[i]) < 0) normal = -normal;
      out[i] = normal;
    }
  }
  return out;
}

std::vector<Eigen::Vector3d> estimate_normals_kdtree(const Cloud& cloud, const std::vector<int>& indices, int k,
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

  std::vector<Eigen::Vector3d> out(indices.size(), Eigen::Vector3d::Constant(kNaN));
  for (std::size_t i = 0; i < normals.size() && i < out.size(); ++i) {
    const Eigen::Vector3d n = normals[i].getNormalVector3fMap().cast<double>();
    if (n.allFinite() && n.norm() > 0.5) out[i] = n.normalized();
  }
  return out;
}

}  // namespace scenewatch::ontology::detail
