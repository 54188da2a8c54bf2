// The segmentation's part of a frame (segmentation_stage.h).
#include "segmentation_stage.h"

#include "frame_sampling.h"
#include "timing.h"

namespace scenewatch::pipeline {

namespace {

Plane to_world(Plane p, const Pose& T) {
  p.normal = T.linear() * p.normal;
  p.centroid = T * p.centroid;
  for (auto& h : p.hull) h = T * h;
  p.d = -p.normal.dot(p.centroid);
  return p;
}

ObjectCluster to_world(ObjectCluster c, const Pose& T) {
  c.centroid = T * c.centroid;
  c.box.center = T * c.box.center;
  c.box.rotation = Eigen::Quaterniond(T.linear()) * c.box.rotation;
  return c;
}

}  // namespace

void segment_frame(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                   FrameResult& result) {
  segmentation::Config seg = config.segmentation;
  if (seg.up) seg.up = T.linear().transpose() * *seg.up;
  const auto t_seg = Clock::now();
  const int stride =
      sample_stride(frame, K, seg.voxel_size_m, config.tracking.max_range_m, config.tracking.segmentation_stride_px);
  segmentation::Segmentation s =
      segmentation::segment_strided(*frame.cloud, seg, Eigen::Vector3d::Zero(), stride, workspace_range(config.tracking));
  result.segment_ms = ms_since(t_seg);
  for (auto& p : s.planes) result.planes.push_back(to_world(std::move(p), T));
  for (auto& o : s.objects) result.objects.push_back(to_world(std::move(o), T));
}

}  // namespace scenewatch::pipeline
