#pragma once
/// A triangle mesh with one colour per vertex (the background's textured mesh).
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace scenewatch {

struct ColoredMesh {
  std::vector<Eigen::Vector3f> vertices;             ///< world frame, metres
  std::vector<std::array<std::uint8_t, 3>> colors;   ///< RGB per vertex
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< vertex indices, counter-clockwise seen from the camera
  bool empty() const { return triangles.empty(); }
  /// Appends another mesh (indices shifted).
  void append(const ColoredMesh& other);
};

}  // namespace scenewatch
