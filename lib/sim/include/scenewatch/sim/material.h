#pragma once
/// Surface appearance: a base colour, an optional procedural texture evaluated in the object's
/// local frame (so that it moves with the object), and transparency for glass.
#include <Eigen/Core>

namespace scenewatch::sim {

/// Procedural textures.
enum class TextureKind {
  kNone,     ///< plain colour
  kChecker,  ///< 3D checkerboard of two colours, period scale_m
  kStripes,  ///< horizontal bands along the local z axis (labels of cans and bottles)
  kNoise,    ///< smooth value noise between the two colours (cardboard, fabric)
  kWood,     ///< grain rings along the local x axis (table tops)
};

/// Printable name ("none", "checker", "stripes", "noise", "wood").
const char* to_string(TextureKind kind);

/// Appearance of one surface. Colours are RGB in 0..255.
struct Material {
  Eigen::Vector3d color = Eigen::Vector3d(180, 180, 180);
  TextureKind texture = TextureKind::kNone;
  Eigen::Vector3d color2 = Eigen::Vector3d(90, 90, 90);  ///< second texture colour
  double scale_m = 0.05;       ///< texture period
  bool transparent = false;    ///< glass: seen in colour, no depth (see SensorConfig)
  double opacity = 0.25;       ///< share of the glass's own colour when transparent
};

/// Albedo (RGB, 0..255) of the material at a point given in the object's local frame.
Eigen::Vector3d albedo(const Material& material, const Eigen::Vector3d& p_local);

}  // namespace scenewatch::sim
