#pragma once
/// Analytic ray casting of a scene of primitives into ideal (noise-free) images: one ray per pixel,
/// nearest hit, Lambert + ambient shading, glass blended over what lies behind it.
#include <cstdint>
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/sim/material.h"
#include "scenewatch/sim/shapes.h"

namespace scenewatch::sim {

/// One primitive placed in the world.
struct RenderItem {
  Shape shape;
  Pose T_world_item = Pose::Identity();  ///< maps the shape's local frame to the world
  Material material;
  std::uint16_t label = 0;               ///< written to the label image where it is nearest
};

/// The room around everything: an axis-aligned box seen from inside (floor, walls, ceiling),
/// label 0. Every ray that starts inside it hits it.
struct Room {
  Eigen::Vector3d min_world = Eigen::Vector3d(-3, -3, 0);
  Eigen::Vector3d max_world = Eigen::Vector3d(3, 3, 2.6);
  Material floor, walls, ceiling;
};

/// A directional light plus ambient term.
struct Lighting {
  Eigen::Vector3d towards_light_world = Eigen::Vector3d(0.3, -0.5, 1.0).normalized();
  double ambient = 0.4;
  double diffuse = 0.7;
};

/// Everything the ray caster draws in one frame.
struct RenderScene {
  std::vector<RenderItem> items;
  Room room;
  Lighting lighting;
};

/// Ideal images of one view, row-major, width * height entries (rgb: 3 per pixel).
struct IdealView {
  int width = 0, height = 0;
  std::vector<float> depth_m;             ///< z of the nearest surface, glass included (inf: none)
  std::vector<float> opaque_depth_m;      ///< z of the nearest opaque surface (inf: none)
  std::vector<float> cos_incidence;       ///< |cos| of the angle between ray and surface normal
  std::vector<float> opaque_cos_incidence;  ///< the same for the nearest opaque surface
  std::vector<std::uint8_t> transparent;  ///< 1 where the nearest surface is glass
  std::vector<float> rgb;                 ///< shaded colour, 0..255
  std::vector<std::uint16_t> labels;      ///< label of the nearest surface
};

/// Options of the ray caster.
struct RaycasterConfig {
  bool cull = true;     ///< bin primitives into screen tiles by their projected boxes, skip those behind the hit
  int tile_px = 16;     ///< tile size for culling
  double near_m = 0.02; ///< rays start this far in front of the camera (in z)
};

/// Renders scenes. Keeps scratch buffers between calls: NOT thread safe, use one per thread.
class Raycaster {
 public:
  /// A ray caster with the given options.
  explicit Raycaster(RaycasterConfig config = {});

  /// Renders the scene seen from T_world_camera (x right, y down, z forward) with intrinsics K
  /// (K must be valid) into `out`, resizing it.
  void render(const RenderScene& scene, const Pose& T_world_camera, const Intrinsics& K, IdealView* out);

 private:
  /// Rebuilds the per-pixel ray tables below when K is not the intrinsics they are for.
  void update_ray_tables(const Intrinsics& K);

  RaycasterConfig config_;
  std::vector<std::vector<std::uint16_t>> tiles_;  ///< candidate items per screen tile
  Intrinsics rays_for_;                            ///< intrinsics the ray tables below are for
  std::vector<double> x_normalized_, y_normalized_;  ///< (u - cx) / fx per column, (v - cy) / fy per row
  std::vector<float> inv_ray_length_;              ///< 1 / |(x, y, 1)| per pixel
};

}  // namespace scenewatch::sim
