// Round containers: see containers.h. Circles are fitted to a piece's footprint on its support
// by the algebraic (Kasa) fit, x^2 + y^2 + D x + E y + F = 0 in least squares.
#include "containers.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <optional>

#include "footprint.h"

namespace scenewatch::segmentation {
namespace {

// At most this many footprint points enter a fit (evenly picked): enough for a circle.
constexpr std::size_t kFitPoints = 400;
// Share of the footprint left out of the refit: a mug's handle is about a tenth of its points.
constexpr std::size_t kTrimPercent = 20;

struct Circle {
  Vec2 center = Vec2::Zero();
  double radius = 0.0;
};

std::optional<Circle> kasa_fit(const std::vector<Vec2>& used) {
  if (used.size() < 10) return std::nullopt;
  Eigen::MatrixX3d A(static_cast<Eigen::Index>(used.size()), 3);
  Eigen::VectorXd b(static_cast<Eigen::Index>(used.size()));
  const Vec2 origin = used.front();  // conditioning: fit relative to a point of the piece
  for (std::size_t i = 0; i < used.size(); ++i) {
    const Vec2 p = used[i] - origin;
    A.row(static_cast<Eigen::Index>(i)) << p.x(), p.y(), 1.0;
    b(static_cast<Eigen::Index>(i)) = -p.squaredNorm();
  }
  const Eigen::Vector3d x = A.colPivHouseholderQr().solve(b);
  const double r2 = (x(0) * x(0) + x(1) * x(1)) / 4 - x(2);
  if (!(r2 > 0)) return std::nullopt;
  return Circle{origin + Vec2(-x(0) / 2, -x(1) / 2), std::sqrt(r2)};
}

// A circle through most of the footprint: fitted, then refitted without the points farthest from
// it (a handle, a stray edge), and accepted when the rest lies close to it.
std::optional<Circle> fit_arc(const std::vector<Vec2>& points, const ContainerParams& params) {
  const std::size_t step = std::max<std::size_t>(1, points.size() / kFitPoints);
  std::vector<Vec2> used;
  for (std::size_t i = 0; i < points.size(); i += step) used.push_back(points[i]);
  auto c = kasa_fit(used);
  if (!c) return std::nullopt;
  auto residual = [&](const Vec2& p) { return std::abs((p - c->center).norm() - c->radius); };
  std::sort(used.begin(), used.end(), [&](const Vec2& a, const Vec2& b) { return residual(a) < residual(b); });
  used.resize(used.size() * (100 - kTrimPercent) / 100);
  c = kasa_fit(used);
  if (!c || c->radius < params.min_radius_m || c->radius > params.max_radius_m) return std::nullopt;
  double sum_sq = 0.0;
  for (const Vec2& p : used) sum_sq += residual(p) * residual(p);
  if (std::sqrt(sum_sq / used.size()) > params.max_rms_ratio * c->radius) return std::nullopt;
  return c;
}

double share_within(const std::vector<Vec2>& points, const Circle& c, double margin) {
  if (points.empty()) return 0.0;
  std::size_t in = 0;
  for (const Vec2& p : points) in += (p - c.center).norm() <= c.radius + margin ? 1 : 0;
  return static_cast<double>(in) / points.size();
}

}  // namespace

std::vector<Piece> join_container_pieces(const Cloud& cloud, std::vector<Piece> pieces, const std::vector<Plane>& planes,
                                         const ContainerParams& params) {
  if (pieces.size() < 2) return pieces;
  std::vector<Footprint> feet;
  std::vector<std::optional<Circle>> arcs;
  for (const Piece& p : pieces) {
    feet.push_back(footprint(cloud, p.indices, planes[p.plane].normal));
    arcs.push_back(fit_arc(feet.back().points, params));
  }
  UnionFind uf(pieces.size());
  for (std::size_t a = 0; a < pieces.size(); ++a) {
    for (std::size_t b = 0; b < pieces.size(); ++b) {
      if (a == b || !arcs[a] || pieces[a].plane != pieces[b].plane) continue;
      const Footprint &fa = feet[a], &fb = feet[b];
      if (fa.low >= fb.high - params.stacking_margin_m || fb.low >= fa.high - params.stacking_margin_m) continue;
      if (share_within(fb.points, *arcs[a], params.wall_margin_m) >= params.min_inside_share) {
        uf.unite(static_cast<int>(a), static_cast<int>(b));
      }
    }
  }
  return join_pieces(pieces, uf);
}

}  // namespace scenewatch::segmentation
