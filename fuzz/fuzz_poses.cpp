// The text files of an RGB-D sequence: a 4x4 pose (frame-NNNNNN.pose.txt), a TUM trajectory
// (trajectory.txt) and the 3x3 camera matrix (camera-intrinsics.txt), each fed the same bytes.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "fuzz_files.h"
#include "scenewatch/io/rgbd.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace scenewatch;
  const auto path = fuzz::write_scratch("input.txt", data, size);
  if (auto pose = io::read_pose_matrix(path); pose.ok()) {
    // Accepted poses are finite and rigid (the reader promises it).
    const Eigen::Matrix4d m = pose->matrix();
    if (!m.allFinite()) std::abort();
    if (std::abs(m.topLeftCorner<3, 3>().determinant() - 1.0) > 1e-3) std::abort();
  }
  if (auto poses = io::read_tum(path); poses.ok()) {
    for (const auto& p : *poses) {
      if (!p.T_world_camera.matrix().allFinite() || !std::isfinite(p.stamp_s)) std::abort();
    }
  }
  if (auto k = io::read_intrinsics(path); k.ok()) {
    if (!std::isfinite(k->fx) || !std::isfinite(k->fy) || !std::isfinite(k->cx) || !std::isfinite(k->cy)) std::abort();
  }
  return 0;
}
