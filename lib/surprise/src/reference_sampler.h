#pragma once
// The colour samples of the expected view: points of the current camera projected into the
// reference keyframes, tested for occlusion against each keyframe's own depth, and read there
// bilinearly, in opponent signals.
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/background/appearance.h"
#include "scenewatch/surprise/expected_view.h"

namespace scenewatch::surprise {

class ReferenceSampler {
 public:
  /// The first min(config.max_samples, kMaxSamples) references with a depth image, in order.
  ReferenceSampler(const std::vector<std::shared_ptr<const background::Keyframe>>& references, const Pose& T_world_camera,
                   const ExpectedViewConfig& config);
  std::size_t size() const { return refs_.size(); }
  /// Samples the given pixels of `view` (each with an expected depth; xn and yn: the normalised
  /// image coordinate of each column and row) and stores their count, mean and ssd.
  void sample(const std::vector<std::uint32_t>& pixels, const std::vector<float>& xn, const std::vector<float>& yn,
              ExpectedView& view) const;

 private:
  // The projection of a point of this camera, q = A p + b (pixel coordinates times depth in the
  // reference), and the reference's images.
  struct Ref {
    Eigen::Matrix3f A;
    Eigen::Vector3f b;
    const std::uint16_t* depth;
    const std::uint8_t* rgb;
    int width;
    float umax, vmax;
  };
  // Where a camera point falls in a reference: pixel coordinates and depth there; z = 0 when
  // outside its image or behind it.
  struct Projection {
    float u, v, z;
  };
  void project(const Ref& ref, const std::vector<float>& px, const std::vector<float>& py, const std::vector<float>& pz,
               std::vector<Projection>& out) const;

  std::vector<Ref> refs_;
  float tol_m_ = 0, tol_rel_ = 0;
};

}  // namespace scenewatch::surprise
