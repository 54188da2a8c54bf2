// The hands of one frame (hand_contact.h): their points in a voxel set, and a box around them that
// rules out most clusters before any point is looked up.
#include "hand_contact.h"

#include "object_points.h"

namespace scenewatch::foreground {
namespace {

constexpr double kBoxSlackM = 0.02;  // a cluster's points lie this close to its box at most

}  // namespace

HandContact::HandContact(const FrameView& f, double contact_m) : hand_(contact_m) {
  VoxelSet hand_points(contact_m);
  Aabb hand_box{Eigen::Vector3d::Constant(1e30), Eigen::Vector3d::Constant(-1e30)};
  if (f.hands) {
    for (const auto& h : f.hands->hands) {
      for (int i : h.tip_indices.empty() ? h.indices : h.tip_indices) {
        const PointT& p = f.cloud->points[static_cast<std::size_t>(i)];
        if (!is_valid(p)) continue;
        const Eigen::Vector3d w = world(p, f.T_world_camera);
        hand_points.insert(w);
        hand_box.min = hand_box.min.cwiseMin(w);
        hand_box.max = hand_box.max.cwiseMax(w);
        any_hand_ = true;
      }
    }
  }
  hand_ = hand_points.dilated();
  // Where a touch can be at all: a point in a cell next to a hand point's is at most two cells
  // from it. A cluster whose box lies farther needs none of its points looked at (the box of a
  // cluster segmented on every second pixel is its samples': its other pixels lie within one
  // segmentation voxel of them, hence kBoxSlackM).
  reach_ = hand_box.grown(2 * contact_m + kBoxSlackM);
}

bool HandContact::may_touch(const ObjectCluster& c) const { return any_hand_ && reach_.overlaps(world_box(c)); }

bool HandContact::touches(const std::vector<Eigen::Vector3d>& pts) const {
  if (!any_hand_) return false;
  for (const auto& p : pts)
    if (hand_.contains(p)) return true;
  return false;
}

}  // namespace scenewatch::foreground
