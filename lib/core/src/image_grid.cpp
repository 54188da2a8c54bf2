#include "scenewatch/core/image_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace scenewatch {
namespace {

struct Ray {
  int index;
  float tx, ty, range;  // float: 1e-7 of a tangent is 1e-4 of a pixel at f = 1000
};

// Nearest integer, for values far inside int's range (pixel coordinates).
inline long nearest(double x) { return static_cast<long>(std::floor(x + 0.5)); }

struct Axis {
  double f = 0;       ///< pixels per unit of tan(angle)
  double c = 0;       ///< pixel of tan = 0
  int size = 0;
};

// The pixel lattice of one axis, when the tangents fall on one: values a + k s for integers k.
// Spacing s = the median gap between distinct values (in a depth image nearly every column
// holds points, so neighbouring values are one column apart), refined by a least-squares line
// through all distinct values against their column numbers. Kept when 99 % of all points lie
// within a tenth of a pixel of a column.
std::optional<Axis> lattice(std::vector<double> t, const std::vector<Ray>& rays, float Ray::*axis_of) {
  if (t.size() < 100) return std::nullopt;
  std::sort(t.begin(), t.end());
  std::vector<double> distinct;
  for (double v : t)
    if (distinct.empty() || v - distinct.back() > 1e-5) distinct.push_back(v);
  // A lattice holds many points per column; scattered rays hardly ever repeat a value.
  if (distinct.size() < 10 || distinct.size() * 3 > t.size()) return std::nullopt;
  std::vector<double> gaps;
  for (std::size_t i = 1; i < distinct.size(); ++i) gaps.push_back(distinct[i] - distinct[i - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  const double s0 = gaps[gaps.size() / 2];
  if (!(s0 > 1e-5)) return std::nullopt;
  // Least squares: distinct[j] = a + s k_j.
  double sk = 0, st = 0, skk = 0, skt = 0;
  const double n = static_cast<double>(distinct.size());
  for (double v : distinct) {
    const double k = static_cast<double>(nearest((v - distinct.front()) / s0));
    sk += k;
    st += v;
    skk += k * k;
    skt += k * v;
  }
  const double den = n * skk - sk * sk;
  if (!(den > 0)) return std::nullopt;
  const double s = (n * skt - sk * st) / den, a = (st - s * sk) / n;
  if (!(s > 0)) return std::nullopt;
  Axis axis;
  axis.f = 1.0 / s;
  axis.c = -a * axis.f;  // column 0 at the smallest tangent
  std::size_t on = 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Ray& r : rays) {
    const double u = r.*axis_of * axis.f + axis.c;
    on += std::abs(u - static_cast<double>(nearest(u))) < 0.1;
    lo = std::min(lo, u), hi = std::max(hi, u);
  }
  if (on * 100 < rays.size() * 99) return std::nullopt;
  axis.c -= static_cast<double>(nearest(lo));  // the first column that holds a point is column 0
  axis.size = static_cast<int>(nearest(hi) - nearest(lo)) + 1;
  return axis;
}

// A virtual pinhole as fine as the rays' angular spacing: the rays' bounding box in tangent space,
// the share of it they cover (on a coarse 64 x 64 grid), and one pixel per point over that area.
Axis virtual_axis(double lo, double hi, double f) {
  Axis axis;
  axis.f = f;
  axis.c = -lo * f + 0.5;
  axis.size = static_cast<int>(std::ceil((hi - lo) * f)) + 1;
  return axis;
}

double density_focal(const std::vector<Ray>& rays, double x0, double x1, double y0, double y1) {
  constexpr int kCells = 64;
  std::vector<char> used(kCells * kCells, 0);
  const double wx = std::max(x1 - x0, 1e-9), wy = std::max(y1 - y0, 1e-9);
  for (const Ray& r : rays) {
    const int a = std::min(kCells - 1, static_cast<int>((r.tx - x0) / wx * kCells));
    const int b = std::min(kCells - 1, static_cast<int>((r.ty - y0) / wy * kCells));
    used[b * kCells + a] = 1;
  }
  const double area = wx * wy * static_cast<double>(std::count(used.begin(), used.end(), 1)) / (kCells * kCells);
  return std::sqrt(static_cast<double>(rays.size()) / area);
}

}  // namespace

std::optional<ImageGrid> recover_image_grid(const Cloud& cloud, const Eigen::Vector3d& sensor_origin,
                                            const Eigen::Quaternionf& sensor_orientation, const ImageGridParams& params) {
  if (cloud.height > 1) return std::nullopt;
  const Eigen::Matrix3d R_t = sensor_orientation.cast<double>().normalized().toRotationMatrix().transpose();
  std::vector<Ray> rays;
  rays.reserve(cloud.size());
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  std::size_t valid = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& p = cloud[i];
    if (!is_valid(p)) continue;
    ++valid;
    const Eigen::Vector3d q = R_t * (p.getVector3fMap().cast<double>() - sensor_origin);
    if (!(q.z() > 1e-6)) continue;
    Ray r{static_cast<int>(i), static_cast<float>(q.x() / q.z()), static_cast<float>(q.y() / q.z()), static_cast<float>(q.norm())};
    x0 = std::min<double>(x0, r.tx), x1 = std::max<double>(x1, r.tx), y0 = std::min<double>(y0, r.ty), y1 = std::max<double>(y1, r.ty);
    rays.push_back(r);
  }
  // One view sees what is in front of it: a cloud with points behind is in another frame.
  if (rays.size() < 100 || rays.size() * 1000 < valid * 999) return std::nullopt;

  // The lattice is found on a sample (every k-th ray) and checked on all.
  const std::size_t step = std::max<std::size_t>(1, rays.size() / 20000);
  std::vector<double> sx, sy;
  for (std::size_t i = 0; i < rays.size(); i += step) sx.push_back(rays[i].tx), sy.push_back(rays[i].ty);
  ImageGrid grid;
  Axis u, v;
  const auto lu = lattice(std::move(sx), rays, &Ray::tx);
  const auto lv = lu ? lattice(std::move(sy), rays, &Ray::ty) : std::nullopt;
  if (lu && lv) {
    u = *lu, v = *lv;
    grid.exact = true;
  } else {
    const double f = density_focal(rays, x0, x1, y0, y1);
    u = virtual_axis(x0, x1, f);
    v = virtual_axis(y0, y1, f);
  }
  if (u.size <= 0 || v.size <= 0 || u.size > params.max_side || v.size > params.max_side) return std::nullopt;
  grid.K.fx = u.f, grid.K.cx = u.c, grid.K.width = u.size;
  grid.K.fy = v.f, grid.K.cy = v.c, grid.K.height = v.size;

  // Each pixel's nearest point stands for it.
  grid.pixel.assign(cloud.size(), -1);
  grid.point.assign(static_cast<std::size_t>(u.size) * v.size, -1);
  std::vector<float> closest(grid.point.size(), std::numeric_limits<float>::infinity());
  for (const Ray& r : rays) {
    const long a = nearest(r.tx * u.f + u.c), b = nearest(r.ty * v.f + v.c);
    if (a < 0 || b < 0 || a >= u.size || b >= v.size) continue;
    const int px = static_cast<int>(b * u.size + a);
    grid.pixel[r.index] = px;
    if (r.range < closest[px]) closest[px] = r.range, grid.point[px] = r.index;
  }
  // Several views: many points lie well behind the point that stands for their pixel.
  std::size_t hidden = 0;
  for (const Ray& r : rays) {
    const int px = grid.pixel[r.index];
    if (px >= 0 && r.range > closest[px] + params.hidden_gap_m + 0.05 * r.range) ++hidden;
  }
  if (static_cast<double>(hidden) > params.max_hidden_share * static_cast<double>(rays.size())) return std::nullopt;
  return grid;
}

Cloud organized_cloud(const Cloud& cloud, const ImageGrid& grid) {
  Cloud out;
  out.width = static_cast<std::uint32_t>(grid.K.width);
  out.height = static_cast<std::uint32_t>(grid.K.height);
  out.is_dense = false;
  PointT nan;
  nan.x = nan.y = nan.z = std::numeric_limits<float>::quiet_NaN();
  out.points.assign(grid.point.size(), nan);
  for (std::size_t px = 0; px < grid.point.size(); ++px)
    if (grid.point[px] >= 0) out.points[px] = cloud[static_cast<std::size_t>(grid.point[px])];
  out.sensor_origin_ = cloud.sensor_origin_;
  out.sensor_orientation_ = cloud.sensor_orientation_;
  return out;
}

}  // namespace scenewatch
