#include "hull2d.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace scenewatch::segmentation {

void plane_basis(const Eigen::Vector3d& n, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = n.unitOrthogonal();
  v = n.cross(u);
}

namespace {

double cross2(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

}  // namespace

namespace {

// Akl-Toussaint: the points extreme along x, y, x + y and x - y span a polygon whose strict
// interior cannot hold a hull vertex; dropping those points first leaves little to sort.
void drop_interior(std::vector<Vec2>& pts) {
  if (pts.size() < 64) return;
  std::array<Vec2, 8> extreme;
  extreme.fill(pts.front());
  for (const Vec2& p : pts) {
    if (p.x() < extreme[0].x()) extreme[0] = p;
    if (p.x() > extreme[1].x()) extreme[1] = p;
    if (p.y() < extreme[2].y()) extreme[2] = p;
    if (p.y() > extreme[3].y()) extreme[3] = p;
    if (p.x() + p.y() < extreme[4].x() + extreme[4].y()) extreme[4] = p;
    if (p.x() + p.y() > extreme[5].x() + extreme[5].y()) extreme[5] = p;
    if (p.x() - p.y() < extreme[6].x() - extreme[6].y()) extreme[6] = p;
    if (p.x() - p.y() > extreme[7].x() - extreme[7].y()) extreme[7] = p;
  }
  const std::vector<Vec2> poly = convex_hull(std::vector<Vec2>(extreme.begin(), extreme.end()));
  if (poly.size() < 3) return;
  pts.erase(std::remove_if(pts.begin(), pts.end(),
                           [&](const Vec2& p) {
                             for (std::size_t i = 0; i < poly.size(); ++i) {
                               if (cross2(poly[i], poly[(i + 1) % poly.size()], p) <= 0) return false;
                             }
                             return true;
                           }),
            pts.end());
}

}  // namespace

std::vector<Vec2> convex_hull(std::vector<Vec2> pts) {
  drop_interior(pts);
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<Vec2> hull(2 * pts.size());
  std::size_t k = 0;
  for (const auto& p : pts) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  return hull;
}

double polygon_area(const std::vector<Vec2>& poly) {
  double a = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * std::abs(a);
}

bool inside_convex(const std::vector<Vec2>& hull, const Vec2& p) {
  if (hull.size() < 3) return false;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    if (cross2(hull[i], hull[(i + 1) % hull.size()], p) < 0) return false;
  }
  return true;
}

}  // namespace scenewatch::segmentation
