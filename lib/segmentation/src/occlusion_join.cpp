// Pieces of one occluded object: see occlusion_join.h. The walk goes along the image line between
// the two pieces' pixel centroids.
#include "occlusion_join.h"

#include <algorithm>
#include <cmath>
#include <limits>


namespace scenewatch::segmentation {
namespace {

constexpr int kNone = -1, kSupport = -2;
// Pixels of each piece's run next to the gap that the depth profile is fitted to.
constexpr int kRunPixels = 40;
// Valid pixels of neither a piece nor the support tolerated on the walk (mixed pixels at edges).
constexpr int kMaxStrayPixels = 3;

struct PieceStats {
  double u = 0, v = 0;  ///< pixel centroid
  double top = 0;       ///< 95th percentile height above its plane
};

PieceStats stats_of(const Cloud& cloud, const Piece& piece, const Plane& plane) {
  PieceStats s;
  std::vector<double> heights;
  heights.reserve(piece.indices.size());
  for (int i : piece.indices) {
    s.u += i % cloud.width;
    s.v += i / cloud.width;
    heights.push_back(plane.signed_distance(cloud[i].getVector3fMap().cast<double>()));
  }
  const double n = static_cast<double>(piece.indices.size());
  s.u /= n;
  s.v /= n;
  const std::size_t k = heights.size() - 1 - heights.size() / 20;
  std::nth_element(heights.begin(), heights.begin() + k, heights.end());
  s.top = heights[k];
  return s;
}

// Whether the walk from piece a to piece b crosses only nearer things (or no data) and one
// surface runs through both behind them.
bool hidden_continuation(const Cloud& cloud, const std::vector<int>& owner, int a, int b, const PieceStats& sa,
                         const PieceStats& sb, const OcclusionParams& params) {
  const int steps = static_cast<int>(std::ceil(std::max(std::abs(sb.u - sa.u), std::abs(sb.v - sa.v))));
  if (steps < 2) return false;
  std::vector<int> line;
  line.reserve(steps + 1);
  for (int k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) / steps;
    const int u = static_cast<int>(std::lround(sa.u + t * (sb.u - sa.u)));
    const int v = static_cast<int>(std::lround(sa.v + t * (sb.v - sa.v)));
    line.push_back(v * static_cast<int>(cloud.width) + u);
  }
  int last_a = -1, first_b = -1;
  for (int k = 0; k <= steps; ++k) {
    if (owner[line[k]] == a && first_b < 0) last_a = k;
    if (owner[line[k]] == b && last_a >= 0 && first_b < 0) first_b = k;
  }
  if (last_a < 0 || first_b < 0 || first_b - last_a < 2) return false;
  int occluder = 0, stray = 0;
  for (int k = last_a + 1; k < first_b; ++k) {
    const int o = owner[line[k]];
    if (o == a || o == b || o == kSupport) return false;  // a glimpse of the support: a real gap
    if (!is_valid(cloud[line[k]])) continue;
    // Unsegmented: a few mixed pixels at a depth edge, or a gap onto something else.
    if (o == kNone && ++stray > kMaxStrayPixels) return false;
    if (o != kNone) ++occluder;
  }
  if (occluder == 0) return false;
  // One plane's profile through both pieces along the walk: a least-squares line in inverse depth
  // (a plane's 1/z is affine in the image, so along an image line it is straight; z itself bends,
  // the more the longer the gap and the more oblique the surface) over each piece's run of pixels
  // next to the gap (up to kRunPixels a side). Fitted over both runs, its slope rests on a
  // baseline as long as the gap it spans; a slope from a few pixels of one side, carried across a
  // gap ten times as wide, would carry ten times its depth noise.
  double sk = 0, sz = 0, skk = 0, skz = 0, m = 0;
  auto take = [&](int k, int piece) {
    if (owner[line[k]] != piece || !is_valid(cloud[line[k]])) return;
    const double w = 1.0 / cloud[line[k]].z;
    sk += k, sz += w, skk += static_cast<double>(k) * k, skz += k * w, m += 1;
  };
  const int a_from = std::max(0, last_a - kRunPixels + 1), b_to = std::min(steps, first_b + kRunPixels - 1);
  for (int k = a_from; k <= last_a; ++k) take(k, a);
  const double ma = m;
  for (int k = first_b; k <= b_to; ++k) take(k, b);
  const double mb = m - ma;
  if (ma < 2 || mb < 2) return false;
  const double den = m * skk - sk * sk;
  const double slope = std::abs(den) < 1e-9 ? 0.0 : (m * skz - sk * sz) / den;
  const double offset = (sz - slope * sk) / m;
  // Between the two runs' positive inverse depths the line stays positive; beyond them a line
  // that reaches zero has left the plane's visible side.
  const auto depth_at = [&](int k) {
    const double w = offset + slope * k;
    return w > 1e-6 ? 1.0 / w : std::numeric_limits<double>::infinity();
  };
  // Each run lies on that line: two surfaces at different angles (two objects side by side) give
  // a line that fits neither.
  const auto rms_about_line = [&](int from, int to, int piece) {
    double sum = 0;
    int n = 0;
    for (int k = from; k <= to; ++k) {
      if (owner[line[k]] != piece || !is_valid(cloud[line[k]])) continue;
      const double r = cloud[line[k]].z - depth_at(k);
      sum += r * r;
      ++n;
    }
    return std::sqrt(sum / std::max(n, 1));
  };
  if (rms_about_line(a_from, last_a, a) > params.max_profile_rms_m ||
      rms_about_line(first_b, b_to, b) > params.max_profile_rms_m) {
    return false;
  }
  // Everything crossed is in front of that surface.
  for (int k = last_a + 1; k < first_b; ++k) {
    const PointT& q = cloud[line[k]];
    if (is_valid(q) && q.z > depth_at(k)) return false;
  }
  // Both pieces lie on it where they meet the gap.
  const PointT &pa = cloud[line[last_a]], &pb = cloud[line[first_b]];
  if (!is_valid(pa) || !is_valid(pb)) return false;
  const auto meets = [&](const PointT& p, int k) {
    return std::abs(depth_at(k) - p.z) <= params.max_depth_gap_m + params.max_depth_gap_rel * p.z;
  };
  return meets(pa, last_a) && meets(pb, first_b);
}

}  // namespace

std::vector<Piece> join_occluded_pieces(const Cloud& cloud, std::vector<Piece> pieces, const std::vector<Plane>& planes,
                                        const OcclusionParams& params) {
  if (cloud.height <= 1 || pieces.size() < 2) return pieces;
  std::vector<int> owner(cloud.size(), kNone);
  for (const Plane& p : planes)
    for (int i : p.indices) owner[i] = kSupport;
  for (std::size_t p = 0; p < pieces.size(); ++p)
    for (int i : pieces[p].indices) owner[i] = static_cast<int>(p);
  std::vector<PieceStats> stats;
  stats.reserve(pieces.size());
  for (const Piece& p : pieces) stats.push_back(stats_of(cloud, p, planes[p.plane]));

  UnionFind uf(pieces.size());
  for (std::size_t a = 0; a < pieces.size(); ++a) {
    for (std::size_t b = a + 1; b < pieces.size(); ++b) {
      if (pieces[a].plane != pieces[b].plane) continue;
      if (std::abs(stats[a].top - stats[b].top) > params.max_height_difference_m) continue;
      const int ia = static_cast<int>(a), ib = static_cast<int>(b);
      // One walk: the profile is fitted to both sides at once, so the walk back would test the
      // same pixels again.
      if (hidden_continuation(cloud, owner, ia, ib, stats[a], stats[b], params)) uf.unite(ia, ib);
    }
  }
  return join_pieces(pieces, uf);
}

}  // namespace scenewatch::segmentation
