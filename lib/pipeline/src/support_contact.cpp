// Whether a cluster rests on its support: see support_contact.h.
#include "support_contact.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::pipeline {

SupportContact support_contact(const std::vector<int>& indices, const Cloud& cloud, const Intrinsics& K,
                               const Eigen::Vector3d& up_camera, double d_camera, double band_m, double link_m,
                               double patch_m) {
  SupportContact c;
  if (cloud.height <= 1 || !K.valid() || static_cast<int>(cloud.width) != K.width || indices.empty()) return c;
  const long w = static_cast<long>(cloud.width), h = static_cast<long>(cloud.height);
  const Eigen::Vector3f up = up_camera.cast<float>();
  const auto height = [&](const PointT& p) { return up.dot(p.getVector3fMap()) + static_cast<float>(d_camera); };
  std::vector<char> in(cloud.points.size(), 0);  // the cluster's pixels
  for (int i : indices) in[static_cast<std::size_t>(i)] = 1;
  const auto in_cluster = [&](long i) { return in[static_cast<std::size_t>(i)] != 0; };
  const float link2 = static_cast<float>(link_m * link_m);
  const float cos45 = static_cast<float>(std::sqrt(0.5));
  // The contacts: band pixels next to the cluster's, with the step from the cluster to them.
  struct Contact {
    long j, du, dv;
    bool operator<(const Contact& o) const { return j < o.j; }
    bool operator==(const Contact& o) const { return j == o.j; }
  };
  std::vector<Contact> band;
  for (int i : indices) {
    const PointT& p = cloud.points[static_cast<std::size_t>(i)];
    if (!is_valid(p)) continue;
    const long u = i % w, v = i / w;
    for (const auto& [du, dv] : {std::pair{1L, 0L}, {-1L, 0L}, {0L, 1L}, {0L, -1L}}) {
      const long qu = u + du, qv = v + dv;
      if (qu < 0 || qu >= w || qv < 0 || qv >= h) continue;
      const long j = qv * w + qu;
      const PointT& q = cloud.points[static_cast<std::size_t>(j)];
      if (!is_valid(q) || std::abs(height(q)) > band_m || in_cluster(j)) continue;
      if ((q.getVector3fMap() - p.getVector3fMap()).squaredNorm() <= link2) band.push_back({j, du, dv});
    }
  }
  std::sort(band.begin(), band.end());
  band.erase(std::unique(band.begin(), band.end()), band.end());
  const auto at = [&](long u, long v) -> const PointT* {
    if (u < 0 || u >= w || v < 0 || v >= h) return nullptr;
    const PointT& p = cloud.points[static_cast<std::size_t>(v * w + u)];
    return is_valid(p) ? &p : nullptr;
  };
  for (const Contact& k : band) {
    // The surface beyond the contact, away from the cluster: a patch_m patch whose near edge lies
    // a patch away from the contact (a patch about it, or starting at it, would take in the strip
    // of the cluster's own side in the band).
    const long qu = k.j % w, qv = k.j / w;
    const long r = std::max(1L, std::lround(0.5 * patch_m * K.fx / cloud.points[static_cast<std::size_t>(k.j)].z));
    const long cu = qu + 2 * r * k.du, cv = qv + 2 * r * k.dv;  // the patch's centre
    const PointT *a = at(cu - r * k.du, cv - r * k.dv), *b = at(cu + r * k.du, cv + r * k.dv);  // across
    const PointT *e = at(cu - r * k.dv, cv - r * k.du), *f = at(cu + r * k.dv, cv + r * k.du);  // along
    if (!a || !b || !e || !f) continue;
    // Only a patch wholly in the band is evidence about the support. One that rises out of it lies
    // on another object (a neighbour in a pile); one that drops below it, on a surface lower than
    // the plane (a table under the book whose top the object was given as its plane, test59's
    // sponge) or on the cluster's own side running on down: the two cannot be told apart here.
    const auto in_band = [&](const PointT* x) { return std::abs(height(*x)) <= band_m; };
    if (!in_band(a) || !in_band(b) || !in_band(e) || !in_band(f)) continue;
    const Eigen::Vector3f n = (b->getVector3fMap() - a->getVector3fMap()).cross(f->getVector3fMap() - e->getVector3fMap());
    if (!(n.norm() > 0)) continue;
    ++c.contacts;
    c.flat += std::abs(n.normalized().dot(up)) >= cos45;
  }
  return c;
}

}  // namespace scenewatch::pipeline
