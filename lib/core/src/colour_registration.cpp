#include "scenewatch/core/colour_registration.h"

#include <algorithm>
#include <cmath>

#include "scenewatch/core/depth_validity.h"

namespace scenewatch {
namespace {

/// A float image with bilinear lookup.
struct Plane {
  int width = 0, height = 0;
  std::vector<float> values;
  float at(int u, int v) const { return values[static_cast<std::size_t>(v) * width + u]; }
  /// Bilinear; only for 0 <= x <= width - 1, 0 <= y <= height - 1.
  float sample(double x, double y) const {
    const int u = std::min(static_cast<int>(x), width - 2), v = std::min(static_cast<int>(y), height - 2);
    const float a = static_cast<float>(x - u), b = static_cast<float>(y - v);
    return (1 - b) * ((1 - a) * at(u, v) + a * at(u + 1, v)) + b * ((1 - a) * at(u, v + 1) + a * at(u + 1, v + 1));
  }
  bool inside(double x, double y) const { return x >= 0 && y >= 0 && x <= width - 1 && y <= height - 1; }
};

/// The Sobel gradient magnitude of the colour's grey level (0..1).
Plane colour_gradient(const Cloud& cloud) {
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  Plane grey{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (std::size_t i = 0; i < grey.values.size(); ++i) {
    const PointT& p = cloud.points[i];
    grey.values[i] = (p.r + p.g + p.b) / (3.0f * 255.0f);
  }
  Plane g{w, h, std::vector<float>(grey.values.size(), 0.0f)};
  for (int v = 1; v + 1 < h; ++v) {
    for (int u = 1; u + 1 < w; ++u) {
      const float gx = (grey.at(u + 1, v - 1) + 2 * grey.at(u + 1, v) + grey.at(u + 1, v + 1)) -
                       (grey.at(u - 1, v - 1) + 2 * grey.at(u - 1, v) + grey.at(u - 1, v + 1));
      const float gy = (grey.at(u - 1, v + 1) + 2 * grey.at(u, v + 1) + grey.at(u + 1, v + 1)) -
                       (grey.at(u - 1, v - 1) + 2 * grey.at(u, v - 1) + grey.at(u + 1, v - 1));
      g.values[static_cast<std::size_t>(v) * w + u] = std::sqrt(gx * gx + gy * gy);
    }
  }
  return g;
}

/// One pass of a box filter of the given radius, along rows or along columns.
Plane box_pass(const Plane& in, int radius, bool along_rows) {
  Plane out = in;
  const int w = in.width, h = in.height, n = along_rows ? w : h;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int at = along_rows ? u : v;
      float sum = 0;
      int count = 0;
      for (int k = std::max(0, at - radius); k <= std::min(n - 1, at + radius); ++k, ++count)
        sum += along_rows ? in.at(k, v) : in.at(u, k);
      out.values[static_cast<std::size_t>(v) * w + u] = sum / count;
    }
  }
  return out;
}

/// A separable box filter of the given radius: widens the gradient's ridges so that a search on
/// a coarse grid of hypotheses still feels the slope towards the right one.
Plane box_blur(const Plane& in, int radius) { return box_pass(box_pass(in, radius, true), radius, false); }

/// The depth camera's principal point, or the image's centre when the intrinsics are unknown.
Eigen::Vector2d principal_point(const Intrinsics& K, int width, int height) {
  return K.fx > 0 && K.fy > 0 ? Eigen::Vector2d(K.cx, K.cy) : Eigen::Vector2d((width - 1) / 2.0, (height - 1) / 2.0);
}

struct EdgePoint {
  float u, v;
};

/// Midpoints between neighbours (right, below) that both have a depth and lie on different
/// surfaces by the sensor's rule (3 sigma of both plus a surface at 75 degrees).
std::vector<EdgePoint> depth_edges(const Cloud& cloud, double focal_px, const SensorModel& sensor) {
  constexpr double kSigmaFactor = 3.0;
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  auto depth = [&](int u, int v) {
    const PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
    return is_valid(p) && p.z > 0 ? static_cast<double>(p.z) : 0.0;
  };
  auto step = [&](double a, double b) {
    return a > 0 && b > 0 && std::abs(a - b) > depth_edge_step_m(sensor, std::min(a, b), focal_px, kSigmaFactor);
  };
  std::vector<EdgePoint> edges;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double z = depth(u, v);
      if (z <= 0) continue;
      if (u + 1 < w && step(z, depth(u + 1, v))) edges.push_back({u + 0.5f, static_cast<float>(v)});
      if (v + 1 < h && step(z, depth(u, v + 1))) edges.push_back({static_cast<float>(u), v + 0.5f});
    }
  }
  return edges;
}

/// The mean gradient at the edges' registered places; 0 when fewer than half of them land in
/// the image (a hypothesis must not win by looking at a few edges only).
double score(const Plane& gradient, const std::vector<EdgePoint>& edges, const ColourRegistration& r, double cx,
             double cy) {
  double sum = 0;
  std::size_t n = 0;
  for (const EdgePoint& e : edges) {
    const double x = cx + r.scale * (e.u - cx) + r.shift_x_px, y = cy + r.scale * (e.v - cy) + r.shift_y_px;
    if (!gradient.inside(x, y)) continue;
    sum += gradient.sample(x, y);
    ++n;
  }
  return 2 * n < edges.size() ? 0.0 : sum / static_cast<double>(n);
}

/// Every `stride`-th edge, so that at most `limit` remain.
std::vector<EdgePoint> thinned(const std::vector<EdgePoint>& edges, std::size_t limit) {
  if (edges.size() <= limit) return edges;
  const std::size_t stride = (edges.size() + limit - 1) / limit;
  std::vector<EdgePoint> out;
  for (std::size_t i = 0; i < edges.size(); i += stride) out.push_back(edges[i]);
  return out;
}

/// The best hypotheses on a grid of scale x shift_x x shift_y around `centre`, at most `keep`,
/// best first, each more than one grid step from every better one.
std::vector<std::pair<double, ColourRegistration>> grid_search(const Plane& gradient, const std::vector<EdgePoint>& edges,
                                                               double cx, double cy, const ColourRegistration& centre,
                                                               double scale_half, double scale_step, double shift_x_half,
                                                               double shift_y_half, double shift_step, std::size_t keep) {
  std::vector<std::pair<double, ColourRegistration>> all;
  for (double s = centre.scale - scale_half; s <= centre.scale + scale_half + 1e-9; s += scale_step) {
    for (double dx = centre.shift_x_px - shift_x_half; dx <= centre.shift_x_px + shift_x_half + 1e-9; dx += shift_step) {
      for (double dy = centre.shift_y_px - shift_y_half; dy <= centre.shift_y_px + shift_y_half + 1e-9; dy += shift_step) {
        const ColourRegistration r{s, dx, dy};
        all.emplace_back(score(gradient, edges, r, cx, cy), r);
      }
    }
  }
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::pair<double, ColourRegistration>> best;
  for (const auto& candidate : all) {
    if (best.size() >= keep) break;
    const bool apart = std::all_of(best.begin(), best.end(), [&](const auto& b) {
      return std::abs(b.second.scale - candidate.second.scale) > 1.5 * scale_step ||
             std::abs(b.second.shift_x_px - candidate.second.shift_x_px) > 1.5 * shift_step ||
             std::abs(b.second.shift_y_px - candidate.second.shift_y_px) > 1.5 * shift_step;
    });
    if (apart) best.push_back(candidate);
  }
  return best;
}

}  // namespace

double ColourRegistration::max_displacement_px(int width, int height, double cx, double cy) const {
  double worst = 0;
  for (const double u : {0.0, width - 1.0}) {
    for (const double v : {0.0, height - 1.0}) {
      worst = std::max(worst, std::hypot((scale - 1) * (u - cx) + shift_x_px, (scale - 1) * (v - cy) + shift_y_px));
    }
  }
  return worst;
}

std::optional<ColourRegistrationFit> fit_colour_registration(const Cloud& organized, const Intrinsics& K,
                                                             const SensorModel& sensor) {
  if (organized.height < 8 || organized.width < 8) return std::nullopt;
  const Eigen::Vector2d c = principal_point(K, static_cast<int>(organized.width), static_cast<int>(organized.height));
  const double cx = c.x(), cy = c.y();
  const std::vector<EdgePoint> edges = depth_edges(organized, K.fx > 0 ? K.fx : 525.0, sensor);
  if (edges.size() < organized.width) return std::nullopt;
  const Plane gradient = colour_gradient(organized);
  // Coarse: every hundredth of scale and every second pixel, on ridges widened by 2 px, with a
  // few thousand edges. Fine: a quarter of that, around the best, on ridges widened by 1 px.
  const Plane wide = box_blur(gradient, 2), narrow = box_blur(gradient, 1);
  // The true peak can fall between the coarse grid's points and lose there to a lesser one (one
  // frame in eight of 7-Scenes' kitchen did): the three best coarse peaks are each refined.
  const std::vector<EdgePoint> many = thinned(edges, 20000);
  ColourRegistrationFit fit;
  fit.score = -1;
  for (const auto& [coarse_score, coarse] :
       grid_search(wide, thinned(edges, 2000), cx, cy, ColourRegistration{1.025, 0, 0}, 0.225, 0.01, 20, 10, 2, 3)) {
    const auto fine = grid_search(narrow, many, cx, cy, coarse, 0.01, 0.0025, 2, 2, 0.5, 1);
    if (!fine.empty() && fine.front().first > fit.score) {
      fit.score = fine.front().first;
      fit.registration = fine.front().second;
    }
  }
  fit.identity_score = score(narrow, many, ColourRegistration{}, cx, cy);
  fit.edge_pixels = edges.size();
  return fit;
}

ColourRemap::ColourRemap(int width, int height, const Intrinsics& K, const ColourRegistration& r)
    : width_(width), height_(height) {
  if (width < 2 || height < 2) return;
  const Eigen::Vector2d c = principal_point(K, width, height);
  const double cx = c.x(), cy = c.y();
  columns_.resize(static_cast<std::size_t>(width));
  rows_.resize(static_cast<std::size_t>(height));
  for (int v = 0; v < height; ++v) {
    const double y = std::clamp(cy + r.scale * (v - cy) + r.shift_y_px, 0.0, height - 1.0);
    const int v0 = std::min(static_cast<int>(y), height - 2);
    rows_[static_cast<std::size_t>(v)] = {v0, static_cast<float>(y - v0)};
  }
  for (int u = 0; u < width; ++u) {
    const double x = std::clamp(cx + r.scale * (u - cx) + r.shift_x_px, 0.0, width - 1.0);
    const int u0 = std::min(static_cast<int>(x), width - 2);
    columns_[static_cast<std::size_t>(u)] = {u0, static_cast<float>(x - u0)};
  }
}

CloudPtr ColourRemap::apply(const Cloud& organized) const {
  auto out = std::make_shared<Cloud>();
  apply(organized, *out);
  return out;
}

void ColourRemap::apply(const Cloud& organized, Cloud& out) const {
  out.header = organized.header;
  out.width = organized.width;
  out.height = organized.height;
  out.is_dense = organized.is_dense;
  out.sensor_origin_ = organized.sensor_origin_;
  out.sensor_orientation_ = organized.sensor_orientation_;
  if (!fits(organized) || rows_.empty()) {
    out.points = organized.points;
    return;
  }
  const auto& in = organized.points;
  out.points.resize(in.size());
  const std::size_t w = static_cast<std::size_t>(width_);
  for (std::size_t v = 0; v < rows_.size(); ++v) {
    const float b = rows_[v].weight;
    const PointT* top = &in[static_cast<std::size_t>(rows_[v].first) * w];
    const PointT* bottom = top + w;
    for (std::size_t u = 0; u < w; ++u) {
      const std::size_t t = static_cast<std::size_t>(columns_[u].first);
      const float a = columns_[u].weight;
      const float w00 = (1 - a) * (1 - b), w10 = a * (1 - b), w01 = (1 - a) * b, w11 = a * b;
      const PointT &p00 = top[t], &p10 = top[t + 1], &p01 = bottom[t], &p11 = bottom[t + 1];
      const std::size_t i = v * w + u;
      PointT& q = out.points[i];
      q = in[i];
      q.r = static_cast<std::uint8_t>(w00 * p00.r + w10 * p10.r + w01 * p01.r + w11 * p11.r + 0.5f);
      q.g = static_cast<std::uint8_t>(w00 * p00.g + w10 * p10.g + w01 * p01.g + w11 * p11.g + 0.5f);
      q.b = static_cast<std::uint8_t>(w00 * p00.b + w10 * p10.b + w01 * p01.b + w11 * p11.b + 0.5f);
    }
  }
}

CloudPtr apply_colour_registration(const Cloud& organized, const Intrinsics& K, const ColourRegistration& r) {
  return ColourRemap(static_cast<int>(organized.width), static_cast<int>(organized.height), K, r).apply(organized);
}

std::optional<ColourRegistration> ColourRegistrationEstimate::update(const Cloud& organized, const Intrinsics& K,
                                                                     const SensorModel& sensor) {
  if (!settled()) {
    ++tried_;
    if (auto fit = fit_colour_registration(organized, K, sensor)) registration_ = fit->registration;
  }
  return registration_;
}

}  // namespace scenewatch
