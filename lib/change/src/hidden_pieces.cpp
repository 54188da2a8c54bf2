// Pieces of one object split by a nearer one, joined: amodal completion in its simplest form (a
// surface cut by an occluder continues behind it; Kanizsa). Colour is no test: mOSD's lying tins
// show a differently printed end on each side of the box in front (learn28: 111 RGB units apart).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "scenewatch/change/frame_objects.h"

namespace scenewatch::change {
namespace {

// Pixel centroid of each object.
std::vector<Eigen::Vector2d> centroids_px(const ObjectLabels& labels, const Cloud& cloud) {
  std::vector<Eigen::Vector2d> out(labels.members.size(), Eigen::Vector2d::Zero());
  for (std::size_t o = 0; o < out.size(); ++o) {
    for (int i : labels.members[o]) out[o] += Eigen::Vector2d(i % cloud.width, i / cloud.width);
    out[o] /= static_cast<double>(std::max<std::size_t>(1, labels.members[o].size()));
  }
  return out;
}

// Walks the pixels from a's centroid to b's: the stretch between the last pixel of a and the
// first of b must be non-empty and every pixel of it in front of both ends.
bool hidden_between(const Cloud& cloud, const ObjectLabels& labels, int a, int b, const Eigen::Vector2d& pa,
                    const Eigen::Vector2d& pb, const Config& config) {
  const Eigen::Vector2d d = pb - pa;
  const int steps = static_cast<int>(std::ceil(d.cwiseAbs().maxCoeff()));
  int last_a = -1, first_b = -1;
  std::vector<std::size_t> line;
  for (int s = 0; s <= steps && first_b < 0; ++s) {
    const Eigen::Vector2d q = pa + d * (steps ? static_cast<double>(s) / steps : 0.0);
    const auto i = static_cast<std::size_t>(std::lround(q.y())) * cloud.width + static_cast<std::size_t>(std::lround(q.x()));
    line.push_back(i);
    const int o = labels.object_of[i];
    if (o == a) last_a = s;
    if (o == b) first_b = s;
  }
  if (last_a < 0 || first_b < 0 || first_b - last_a < 2) return false;
  // Pixels without depth are allowed (the sensor's shadow beside an occluder's edge), as long as
  // most of the stretch shows the occluder.
  const float z_end = std::min(cloud.points[line[last_a]].z, cloud.points[line[first_b]].z);
  int in_front = 0;
  for (int s = last_a + 1; s < first_b; ++s) {
    const PointT& p = cloud.points[line[s]];
    if (!is_valid(p)) continue;
    if (p.z > z_end - tolerance_m(config, p.z)) return false;
    ++in_front;
  }
  return 2 * in_front > first_b - last_a - 1;
}

int root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

void join_hidden_pieces(ObjectLabels& labels, const Cloud& cloud, const Config& config) {
  if (cloud.height <= 1 || labels.members.size() < 2) return;
  const std::vector<Eigen::Vector2d> centroid = centroids_px(labels, cloud);
  const int n = static_cast<int>(centroid.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  bool joined = false;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      if (!hidden_between(cloud, labels, a, b, centroid[a], centroid[b], config)) continue;
      parent[root(parent, b)] = root(parent, a);
      joined = true;
    }
  if (!joined) return;
  ObjectLabels out;
  out.object_of.assign(labels.object_of.size(), -1);
  std::vector<int> id(n, -1);
  for (int o = 0; o < n; ++o) {
    const int r = root(parent, o);
    if (id[r] < 0) {
      id[r] = static_cast<int>(out.members.size());
      out.members.emplace_back();
    }
    auto& m = out.members[id[r]];
    m.insert(m.end(), labels.members[o].begin(), labels.members[o].end());
  }
  for (std::size_t k = 0; k < out.members.size(); ++k) {
    std::sort(out.members[k].begin(), out.members[k].end());
    for (int i : out.members[k]) out.object_of[i] = static_cast<int>(k);
  }
  labels = std::move(out);
}

}  // namespace scenewatch::change
