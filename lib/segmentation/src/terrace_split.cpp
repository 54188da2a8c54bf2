#include "terrace_split.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include <Eigen/Eigenvalues>

#include "part_image.h"

namespace scenewatch::segmentation {
namespace {

struct Face {
  std::vector<int> pixels;  ///< box pixels (indices into PartImage::local)
  double low = 0.0, high = 0.0, depth = 0.0;  ///< its heights' 10th and 90th percentiles, median depth
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  ///< least-squares plane
  double width = 0.0;  ///< the spread across its narrower in-plane axis (m, one sigma)
};

// Calls f(q) for each 4-neighbour q of box pixel p (an index into image.local) inside the box.
template <typename F>
void for_each_neighbour(const PartImage& image, std::size_t p, F&& f) {
  const int u = static_cast<int>(p % static_cast<std::size_t>(image.bw)), v = static_cast<int>(p / static_cast<std::size_t>(image.bw));
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  for (int e = 0; e < 4; ++e) {
    const int uu = u + du[e], vv = v + dv[e];
    if (uu >= 0 && vv >= 0 && uu < image.bw && vv < image.bh) f(static_cast<std::size_t>(vv) * image.bw + uu);
  }
}

double quantile(std::vector<double> v, double q) {
  const auto k = static_cast<long>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

}  // namespace

std::vector<std::vector<int>> split_at_terraces(const Cloud& cloud, std::vector<int> part, const Eigen::Vector3d& n, double d,
                                                const TerraceParams& params) {
  std::vector<std::vector<int>> unchanged;
  unchanged.push_back(part);
  if (cloud.height <= 1 || static_cast<int>(part.size()) < 2 * params.min_points) return unchanged;
  const PartImage image(cloud, part);
  const std::size_t m = image.local.size();
  // The cloud index of a box pixel, -1 outside the part.
  const auto cloud_at = [&](std::size_t p) { return image.local[p] < 0 ? -1 : part[static_cast<std::size_t>(image.local[p])]; };
  const auto cloud_near = [&](int u, int v) {  // the same at box pixel (u, v), -1 outside the box
    const int k = image.find(image.u0 + u, image.v0 + v);
    return k < 0 ? -1 : part[static_cast<std::size_t>(k)];
  };

  const auto point = [&](int i) { return cloud.points[static_cast<std::size_t>(i)].getVector3fMap().cast<double>(); };
  const auto gap = [&](double z) { return params.sigma_factor * std::sqrt(2.0) * params.sensor.sigma_z(z); };
  std::vector<float> height(m, 0.0f), depth(m, 0.0f);
  std::vector<char> level(m, 0);
  const double cos_tilt = std::cos(params.max_tilt_deg * M_PI / 180.0);
  constexpr int k = 2;  // normals from neighbours two pixels away
  for (int v = 0; v < image.bh; ++v)
    for (int u = 0; u < image.bw; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * image.bw + u;
      const int i = cloud_at(p);
      if (i < 0) continue;
      const Eigen::Vector3d q = point(i);
      height[p] = static_cast<float>(n.dot(q) + d);
      depth[p] = cloud.points[static_cast<std::size_t>(i)].z;
      const int l = cloud_near(u - k, v), r = cloud_near(u + k, v), t = cloud_near(u, v - k), b = cloud_near(u, v + k);
      if (l < 0 || r < 0 || t < 0 || b < 0) continue;
      const Eigen::Vector3d normal = (point(r) - point(l)).cross(point(b) - point(t));
      const double norm = normal.norm();
      if (norm > 0 && std::abs(normal.dot(n)) >= cos_tilt * norm) level[p] = 1;
    }

  // Level faces: 4-connected level pixels whose heights agree within the noise.
  std::vector<int> face_of(m, -1);
  std::vector<Face> faces;
  for (std::size_t s = 0; s < m; ++s) {
    if (!level[s] || face_of[s] >= 0) continue;
    Face f;
    std::deque<std::size_t> queue{s};
    face_of[s] = static_cast<int>(faces.size());
    while (!queue.empty()) {
      const std::size_t p = queue.front();
      queue.pop_front();
      f.pixels.push_back(static_cast<int>(p));
      for_each_neighbour(image, p, [&](std::size_t q) {
        if (!level[q] || face_of[q] >= 0 || std::abs(height[q] - height[p]) > gap(depth[p])) return;
        face_of[q] = face_of[s];
        queue.push_back(q);
      });
    }
    faces.push_back(std::move(f));
  }
  // Object-sized faces become seeds.
  std::vector<Face> seeds;
  for (Face& f : faces) {
    if (static_cast<int>(f.pixels.size()) < params.min_points) continue;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    std::vector<double> hs, zs;
    for (int p : f.pixels) {
      const Eigen::Vector3d q = point(cloud_at(static_cast<std::size_t>(p)));
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
      hs.push_back(height[static_cast<std::size_t>(p)]);
      zs.push_back(depth[static_cast<std::size_t>(p)]);
    }
    if ((hi - lo).norm() < params.min_size_m) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int p : f.pixels) c += point(cloud_at(static_cast<std::size_t>(p)));
    c /= static_cast<double>(f.pixels.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int p : f.pixels) {
      const Eigen::Vector3d e = point(cloud_at(static_cast<std::size_t>(p))) - c;
      cov += e * e.transpose();
    }
    f.centroid = c;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    f.normal = eig.eigenvectors().col(0);
    f.width = std::sqrt(std::max(0.0, eig.eigenvalues()(1)) / static_cast<double>(f.pixels.size()));
    f.low = quantile(hs, 0.1);
    f.high = quantile(hs, 0.9);
    f.depth = quantile(zs, 0.5);
    seeds.push_back(std::move(f));
  }
  // Faces whose heights overlap within the noise are one level (one surface, or surfaces the sensor
  // cannot tell apart): merged until no two overlap.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t a = 0; a < seeds.size() && !merged; ++a)
      for (std::size_t b = a + 1; b < seeds.size() && !merged; ++b) {
        const double g = gap(std::max(seeds[a].depth, seeds[b].depth));
        // Apart in height, and not one plane seen in two pieces (a tilted face around something
        // standing on it): the median distance of one face's points from the other's plane. The
        // plane is the wider face's: a strip's plane is ill-determined across it, so extended
        // over the other face it can miss by more than the noise (a leaning box's lid in pieces
        // around the box on it).
        const auto off_plane = [&](const Face& from, const Face& to) {
          std::vector<double> dist;
          for (int p : to.pixels) dist.push_back(std::abs(from.normal.dot(point(cloud_at(static_cast<std::size_t>(p))) - from.centroid)));
          return quantile(dist, 0.5);
        };
        const bool apart_in_height = seeds[a].low > seeds[b].high + g || seeds[b].low > seeds[a].high + g;
        const bool a_wider = seeds[a].width >= seeds[b].width;
        if (apart_in_height && (a_wider ? off_plane(seeds[a], seeds[b]) : off_plane(seeds[b], seeds[a])) > g) continue;
        Face& f = seeds[a];
        f.pixels.insert(f.pixels.end(), seeds[b].pixels.begin(), seeds[b].pixels.end());
        f.low = std::min(f.low, seeds[b].low), f.high = std::max(f.high, seeds[b].high);
        f.depth = std::max(f.depth, seeds[b].depth);
        if (!a_wider) f.centroid = seeds[b].centroid, f.normal = seeds[b].normal, f.width = seeds[b].width;
        seeds.erase(seeds.begin() + static_cast<long>(b));
        merged = true;
      }
  }
  if (seeds.size() < 2) return unchanged;
  // Each level first takes its own band of heights: from above the next lower level to its top.
  std::sort(seeds.begin(), seeds.end(), [](const Face& a, const Face& b) { return a.high < b.high; });
  std::vector<double> band_low(seeds.size(), -1e9);
  for (std::size_t j = 1; j < seeds.size(); ++j) band_low[j] = seeds[j - 1].high + gap(seeds[j - 1].depth);

  // Every pixel goes to the level whose band it lies in, spreading through the image from that
  // level's face (nearest first); what no level reaches so, to the nearest level. (A merged
  // level keeps the plane of its widest face.)
  std::vector<int> owner(m, -1);
  for (int pass = 0; pass < 2; ++pass) {
    std::deque<std::size_t> queue;
    for (std::size_t p = 0; p < m; ++p)
      if (owner[p] >= 0) queue.push_back(p);
    if (pass == 0)
      for (std::size_t s = 0; s < seeds.size(); ++s)
        for (int p : seeds[s].pixels) owner[static_cast<std::size_t>(p)] = static_cast<int>(s), queue.push_back(static_cast<std::size_t>(p));
    while (!queue.empty()) {
      const std::size_t p = queue.front();
      queue.pop_front();
      const Face& f = seeds[static_cast<std::size_t>(owner[p])];
      for_each_neighbour(image, p, [&](std::size_t q) {
        if (image.local[q] < 0 || owner[q] >= 0) return;
        if (pass == 0 && (height[q] > f.high + gap(depth[q]) || height[q] <= band_low[static_cast<std::size_t>(owner[p])])) return;
        owner[q] = owner[p];
        queue.push_back(q);
      });
    }
  }
  std::vector<std::vector<int>> pieces(seeds.size());
  std::vector<int> stray;
  for (std::size_t p = 0; p < m; ++p) {
    if (image.local[p] < 0) continue;
    (owner[p] >= 0 ? pieces[static_cast<std::size_t>(owner[p])] : stray).push_back(cloud_at(p));
  }
  for (const auto& piece : pieces)
    if (static_cast<int>(piece.size()) < params.min_points) return unchanged;
  if (!stray.empty()) pieces.push_back(std::move(stray));  // parts of the part no face reaches in the image
  return pieces;
}

}  // namespace scenewatch::segmentation
