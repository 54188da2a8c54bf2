#include "scenewatch/sim/raycaster.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

#include "shape_math.h"
#include "texture_math.h"

namespace scenewatch::sim {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr float kInf = std::numeric_limits<float>::infinity();

/// One item prepared for a frame: the camera origin and the camera-to-local rotation in the
/// item's frame, so that a pixel's ray is one 3x3 product away.
struct Prepared {
  const RenderItem* item = nullptr;
  Vector3d origin_local;
  Matrix3d R_local_camera;
  Matrix3d R_world_local;
  bool transparent = false;
  double z_min_m = 0.0;                    ///< nearest depth any of its points can have in this view
  bool sphere_test = false;                ///< test the bounding sphere before the shape
  Vector3d sphere_center_local;
  double sphere_radius2 = 0.0;
};

/// Screen rectangle [u0, u1] x [v0, v1] (inclusive) that holds the projection of a local box
/// placed by T_camera_local; false when it lies behind the near plane or off the image. A box that
/// crosses the near plane gets the whole image.
bool project_box(const Pose& T_camera_local, const Vector3d& lo, const Vector3d& hi, const Intrinsics& K,
                 double near_m, int* u0, int* u1, int* v0, int* v1, double* z_min) {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min, y_min = x_min, y_max = -x_min;
  int behind = 0;
  *z_min = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i) {
    const Vector3d corner((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
    const Vector3d c = T_camera_local * corner;
    *z_min = std::min(*z_min, c.z());
    if (c.z() < near_m) {
      ++behind;
      continue;
    }
    x_min = std::min(x_min, c.x() / c.z());
    x_max = std::max(x_max, c.x() / c.z());
    y_min = std::min(y_min, c.y() / c.z());
    y_max = std::max(y_max, c.y() / c.z());
  }
  if (behind == 8) return false;
  if (behind > 0) {
    *u0 = 0; *v0 = 0; *u1 = K.width - 1; *v1 = K.height - 1;
    return true;
  }
  // The projection of a convex body lies in the convex hull of its box's projected corners.
  const double fu0 = std::floor(K.fx * x_min + K.cx) - 1, fu1 = std::ceil(K.fx * x_max + K.cx) + 1;
  const double fv0 = std::floor(K.fy * y_min + K.cy) - 1, fv1 = std::ceil(K.fy * y_max + K.cy) + 1;
  if (fu1 < 0 || fv1 < 0 || fu0 > K.width - 1 || fv0 > K.height - 1) return false;
  *u0 = static_cast<int>(std::max(fu0, 0.0));
  *v0 = static_cast<int>(std::max(fv0, 0.0));
  *u1 = static_cast<int>(std::min(fu1, K.width - 1.0));
  *v1 = static_cast<int>(std::min(fv1, K.height - 1.0));
  return true;
}


/// Lambert + ambient factor for a surface normal seen along a ray.
inline double light_factor(const Vector3d& normal_world, const Vector3d& ray_world, const Lighting& light) {
  const double nl = normal_world.dot(light.towards_light_world);
  // Lit from the side the camera sees.
  const double lambert = normal_world.dot(ray_world) > 0 ? -nl : nl;
  return light.ambient + light.diffuse * std::max(0.0, lambert);
}

constexpr std::uint16_t kLabelNone = 0;

/// A glass surface along a ray.
struct GlassLayer {
  double t;
  std::size_t item;
  Vector3d normal_local;
};
using GlassLayers = std::vector<GlassLayer>;

/// Blends the glass items of a tile that lie in front of t_opaque over `color`, far to near, and
/// leaves the layers (nearest last) in `layers`. Returns false when the ray meets no glass.
bool blend_glass(const Prepared* items, const std::uint16_t* list, std::size_t list_size, const Vector3d& d_c,
                 const Vector3d& d_w, double inv_len, double t_opaque, double near_m, const Lighting& light,
                 GlassLayers* layers, Vector3d* color) {
  layers->clear();
  ShapeHit hit;
  for (std::size_t k = 0; k < list_size; ++k) {
    const Prepared& p = items[list[k]];
    if (!p.transparent || p.z_min_m >= t_opaque) continue;
    const Vector3d d_l = p.R_local_camera * d_c;
    if (detail::intersect_inline(p.item->shape, p.origin_local, d_l, near_m, t_opaque, &hit)) {
      layers->push_back({hit.t, list[k], hit.normal});
    }
  }
  if (layers->empty()) return false;
  std::sort(layers->begin(), layers->end(), [](const GlassLayer& a, const GlassLayer& b) { return a.t > b.t; });
  for (const GlassLayer& layer : *layers) {
    const Prepared& p = items[layer.item];
    const Vector3d d_l = p.R_local_camera * d_c;
    const Vector3d n_w = p.R_world_local * layer.normal_local;
    const double c = std::abs(n_w.dot(d_w)) * inv_len;
    // Glass looks more solid at grazing angles (a Fresnel-like rim).
    const double rim = (1.0 - c) * (1.0 - c) * (1.0 - c);
    const double opacity = p.item->material.opacity;
    const double alpha = std::clamp(opacity + (1.0 - opacity) * rim, 0.0, 1.0);
    const Vector3d own =
        detail::albedo_inline(p.item->material, p.origin_local + layer.t * d_l) * light_factor(n_w, d_w, light);
    *color = alpha * own + (1.0 - alpha) * *color;
  }
  return true;
}

/// The room seen from one camera position: distances from the camera to the six faces.
struct RoomView {
  double to_max[3];  ///< to the max face along each axis (positive inside the room)
  double to_min[3];  ///< to the min face
  bool inside = false;
};

RoomView room_view(const Room& room, const Vector3d& o) {
  RoomView r;
  r.inside = true;
  for (int i = 0; i < 3; ++i) {
    r.to_max[i] = room.max_world[i] - o[i];
    r.to_min[i] = o[i] - room.min_world[i];
    r.inside = r.inside && r.to_max[i] > 0 && r.to_min[i] > 0;
  }
  return r;
}

/// Exit of a ray from inside the room: t, the axis and the side (+1: max face). The nearest face
/// is found by cross-multiplying distances and direction components (no division but one).
inline bool room_exit(const RoomView& r, const Vector3d& d, double* t, int* axis, int* side) {
  if (!r.inside) return false;
  const double ax = std::abs(d.x()), ay = std::abs(d.y()), az = std::abs(d.z());
  const double nx = d.x() > 0 ? r.to_max[0] : r.to_min[0];
  const double ny = d.y() > 0 ? r.to_max[1] : r.to_min[1];
  const double nz = d.z() > 0 ? r.to_max[2] : r.to_min[2];
  // n_i / a_i is the distance to the face; a zero a_i never wins (its ratio is infinite).
  const bool x_first = nx * ay < ny * ax;
  double n = x_first ? nx : ny, a = x_first ? ax : ay;
  int i = x_first ? 0 : 1;
  if (nz * a < n * az) {
    n = nz;
    a = az;
    i = 2;
  }
  if (!(a > 0)) return false;
  *t = n / a;
  *axis = i;
  *side = d[i] > 0 ? 1 : -1;
  return true;
}


/// Per-frame preparation of every item.
std::vector<Prepared> prepare_items(const RenderScene& scene, const Pose& T_world_camera) {
  const Matrix3d R_wc = T_world_camera.linear();
  const Vector3d o_w = T_world_camera.translation();
  std::vector<Prepared> prepared(scene.items.size());
  for (std::size_t i = 0; i < scene.items.size(); ++i) {
    const RenderItem& item = scene.items[i];
    Prepared& p = prepared[i];
    p.item = &item;
    p.R_world_local = item.T_world_item.linear();
    const Matrix3d R_lw = p.R_world_local.transpose();
    p.origin_local = R_lw * (o_w - item.T_world_item.translation());
    p.R_local_camera = R_lw * R_wc;
    p.transparent = item.material.transparent;
    p.z_min_m = -std::numeric_limits<double>::infinity();
    // Boxes are as cheap to test as their spheres; the others get a sphere test first.
    p.sphere_test = item.shape.kind != ShapeKind::kBox;
    double r = 0.0;
    bounding_sphere(item.shape, &p.sphere_center_local, &r);
    p.sphere_radius2 = r * r;
  }
  return prepared;
}

/// Screen tiles (`tile` pixels square, tiles_x a row) with the items whose bounding boxes project
/// onto them, nearest first; with `cull`, each item's z_min_m is set.
void bin_into_tiles(std::vector<Prepared>& prepared, const Pose& T_world_camera, const Intrinsics& K, bool cull,
                    double near_m, int tile, int tiles_x, int tiles_y, std::vector<std::vector<std::uint16_t>>* tiles) {
  const int W = K.width, H = K.height;
  const Pose T_camera_world = T_world_camera.inverse();
  tiles->resize(static_cast<std::size_t>(tiles_x) * tiles_y);
  for (auto& list : *tiles) list.clear();
  std::vector<std::array<int, 4>> boxes(prepared.size(), {0, W - 1, 0, H - 1});
  std::vector<bool> visible(prepared.size(), true);
  if (cull) {
    for (std::size_t i = 0; i < prepared.size(); ++i) {
      Vector3d lo, hi;
      bounding_box(prepared[i].item->shape, &lo, &hi);
      auto& b = boxes[i];
      visible[i] = project_box(T_camera_world * prepared[i].item->T_world_item, lo, hi, K, near_m, &b[0], &b[1],
                               &b[2], &b[3], &prepared[i].z_min_m);
    }
  }
  // Near items first: they shorten the ray early, and items that cannot come nearer than the
  // current hit (z_min >= t, as t is the depth) are skipped.
  std::vector<std::size_t> order(prepared.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return prepared[a].z_min_m < prepared[b].z_min_m; });
  for (std::size_t i : order) {
    if (!visible[i]) continue;
    const int u0 = boxes[i][0], u1 = boxes[i][1], v0 = boxes[i][2], v1 = boxes[i][3];
    for (int ty = v0 / tile; ty <= v1 / tile; ++ty) {
      for (int tx = u0 / tile; tx <= u1 / tile; ++tx) {
        (*tiles)[static_cast<std::size_t>(ty) * tiles_x + tx].push_back(static_cast<std::uint16_t>(i));
      }
    }
  }
}

/// Where the ray d_w from o_w leaves the room (farther than near_m): its depth, normal and lit
/// colour; false when it leaves nowhere, the outputs untouched then.
inline bool room_surface(const Room& room, const RoomView& room_from_camera, const Vector3d& o_w, const Vector3d& d_w,
                         double near_m, const Lighting& light, double* t_best, Vector3d* normal_w, Vector3d* color) {
  double t_room = 0;
  int axis = 2, side = -1;
  const bool have_opaque = room_exit(room_from_camera, d_w, &t_room, &axis, &side) && t_room > near_m;
  if (have_opaque) {
    *t_best = t_room;
    *normal_w = Vector3d::Zero();
    (*normal_w)[axis] = -side;
    const Material& m = axis == 2 ? (side < 0 ? room.floor : room.ceiling) : room.walls;
    *color = detail::albedo_inline(m, o_w + t_room * d_w) * light_factor(*normal_w, d_w, light);
  }
  return have_opaque;
}

/// The nearest opaque surface along d_c (camera frame, z = 1) among a tile's items, sorted near
/// to far and skipped when they cannot be nearer; null when none is nearer than t_best.
inline const Prepared* nearest_opaque(const Prepared* items, const std::uint16_t* list, std::size_t list_size,
                                      const Vector3d& d_c, double near_m, double* t_best, ShapeHit* best_hit,
                                      Vector3d* best_dir_local) {
  const Prepared* best = nullptr;
  ShapeHit hit;
  for (std::size_t k = 0; k < list_size; ++k) {
    const Prepared& p = items[list[k]];
    if (p.transparent || p.z_min_m >= *t_best) continue;
    const Vector3d d_l = p.R_local_camera * d_c;
    if (p.sphere_test) {
      // Bounding sphere first (no division): a miss when the origin is outside it and
      // the ray's closest approach is farther than the radius.
      const Vector3d oc = p.sphere_center_local - p.origin_local;
      const double b = oc.dot(d_l), c = oc.squaredNorm() - p.sphere_radius2;
      if (c > 0.0 && (b <= 0.0 || b * b < c * d_l.squaredNorm())) continue;
    }
    if (detail::intersect_inline(p.item->shape, p.origin_local, d_l, near_m, *t_best, &hit)) {
      *t_best = hit.t;
      best = &p;
      *best_hit = hit;
      *best_dir_local = d_l;
    }
  }
  return best;
}

}  // namespace

Raycaster::Raycaster(RaycasterConfig config) : config_(config) {}

void Raycaster::update_ray_tables(const Intrinsics& K) {
  const int W = K.width, H = K.height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  if (rays_for_.fx != K.fx || rays_for_.fy != K.fy || rays_for_.cx != K.cx || rays_for_.cy != K.cy ||
      rays_for_.width != W || rays_for_.height != H) {
    rays_for_ = K;
    x_normalized_.resize(static_cast<std::size_t>(W));
    y_normalized_.resize(static_cast<std::size_t>(H));
    inv_ray_length_.resize(n);
    for (int u = 0; u < W; ++u) x_normalized_[static_cast<std::size_t>(u)] = (u - K.cx) / K.fx;
    for (int v = 0; v < H; ++v) y_normalized_[static_cast<std::size_t>(v)] = (v - K.cy) / K.fy;
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const double x = x_normalized_[static_cast<std::size_t>(u)], y = y_normalized_[static_cast<std::size_t>(v)];
        inv_ray_length_[static_cast<std::size_t>(v) * W + u] = static_cast<float>(1.0 / std::sqrt(x * x + y * y + 1.0));
      }
    }
  }
}

void Raycaster::render(const RenderScene& scene, const Pose& T_world_camera, const Intrinsics& K, IdealView* out) {
  assert(K.valid());
  const int W = K.width, H = K.height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  out->width = W;
  out->height = H;
  // Every pixel is written below: resize, no fill.
  out->depth_m.resize(n);
  out->opaque_depth_m.resize(n);
  out->cos_incidence.resize(n);
  out->opaque_cos_incidence.resize(n);
  out->transparent.resize(n);
  out->rgb.resize(3 * n);
  out->labels.resize(n);

  // Per-pixel ray tables, rebuilt only when the intrinsics change.
  update_ray_tables(K);

  const Matrix3d R_wc = T_world_camera.linear();
  const Vector3d o_w = T_world_camera.translation();
  std::vector<Prepared> prepared = prepare_items(scene, T_world_camera);
  const int tile = std::max(1, config_.tile_px);
  const int tiles_x = (W + tile - 1) / tile, tiles_y = (H + tile - 1) / tile;
  bin_into_tiles(prepared, T_world_camera, K, config_.cull, config_.near_m, tile, tiles_x, tiles_y, &tiles_);

  // Locals and raw pointers: the byte stores below may alias anything, so nothing the loop reads
  // should live behind a pointer the compiler has to reload.
  const Lighting light = scene.lighting;
  const Room& room = scene.room;
  const RoomView room_from_camera = room_view(room, o_w);
  const double near_m = config_.near_m;
  const double* xs = x_normalized_.data();
  const double* ys = y_normalized_.data();
  const float* inv_lengths = inv_ray_length_.data();
  const Prepared* items = prepared.data();
  float* depth_out = out->depth_m.data();
  float* opaque_depth_out = out->opaque_depth_m.data();
  float* cos_out = out->cos_incidence.data();
  float* opaque_cos_out = out->opaque_cos_incidence.data();
  std::uint8_t* glass_out = out->transparent.data();
  float* rgb_out = out->rgb.data();
  std::uint16_t* label_out = out->labels.data();
  const Vector3d c0 = R_wc.col(0), c1 = R_wc.col(1), c2 = R_wc.col(2);

  GlassLayers glass;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const auto& tile_list = tiles_[static_cast<std::size_t>(ty) * tiles_x + tx];
      const std::uint16_t* list = tile_list.data();
      const std::size_t list_size = tile_list.size();
      bool tile_has_glass = false;
      for (std::size_t k = 0; k < list_size; ++k) tile_has_glass = tile_has_glass || items[list[k]].transparent;
      const int v_end = std::min(H, (ty + 1) * tile), u_end = std::min(W, (tx + 1) * tile);
      for (int v = ty * tile; v < v_end; ++v) {
        const double yn = ys[v];
        const Vector3d row = yn * c1 + c2;
        for (int u = tx * tile; u < u_end; ++u) {
          const double xn = xs[u];
          const Vector3d d_c(xn, yn, 1.0);  // z = 1: the ray parameter t is the depth
          const Vector3d d_w = xn * c0 + row;
          const std::size_t pix = static_cast<std::size_t>(v) * W + u;
          const double inv_len = inv_lengths[pix];

          double t_best = std::numeric_limits<double>::infinity();
          ShapeHit best_hit;
          Vector3d best_dir_local;
          const Prepared* best = nearest_opaque(items, list, list_size, d_c, near_m, &t_best, &best_hit, &best_dir_local);

          Vector3d color = Vector3d::Zero();
          Vector3d normal_w;
          std::uint16_t label = kLabelNone;
          bool have_opaque = true;
          if (best != nullptr) {
            const Vector3d pt_local = best->origin_local + best_hit.t * best_dir_local;
            normal_w = best->R_world_local * best_hit.normal;
            color = detail::albedo_inline(best->item->material, pt_local) * light_factor(normal_w, d_w, light);
            label = best->item->label;
          } else {
            have_opaque = room_surface(room, room_from_camera, o_w, d_w, near_m, light, &t_best, &normal_w, &color);
          }
          float cos_inc = have_opaque ? static_cast<float>(std::abs(normal_w.dot(d_w)) * inv_len) : 0.0f;
          float depth = have_opaque ? static_cast<float>(t_best) : kInf;
          opaque_depth_out[pix] = depth;
          opaque_cos_out[pix] = cos_inc;
          std::uint8_t is_glass = 0;

          // Glass in front of it, blended from far to near (rare: only tiles that hold glass).
          if (tile_has_glass &&
              blend_glass(items, list, list_size, d_c, d_w, inv_len, t_best, near_m, light, &glass, &color)) {
            const GlassLayer& front = glass.back();
            const Vector3d n_w = items[front.item].R_world_local * front.normal_local;
            cos_inc = static_cast<float>(std::abs(n_w.dot(d_w)) * inv_len);
            depth = static_cast<float>(front.t);
            label = items[front.item].item->label;
            is_glass = 1;
          }

          depth_out[pix] = depth;
          cos_out[pix] = cos_inc;
          label_out[pix] = label;
          rgb_out[3 * pix + 0] = static_cast<float>(std::min(color.x(), 255.0));
          rgb_out[3 * pix + 1] = static_cast<float>(std::min(color.y(), 255.0));
          rgb_out[3 * pix + 2] = static_cast<float>(std::min(color.z(), 255.0));
          glass_out[pix] = is_glass;
        }
      }
    }
  }
}

}  // namespace scenewatch::sim
