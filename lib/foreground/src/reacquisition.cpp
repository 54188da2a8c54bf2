// Reacquisition (reacquisition.h): a lost foreground object found again, in a hand or near its
// last place.
#include "reacquisition.h"

#include <cmath>

#include "object_points.h"
#include "skin_model.h"

namespace scenewatch::foreground {

void reseed_in_hand(TouchedObject& o, const FrameView& f, const std::vector<ObjectCluster>& clusters,
                    const HandContact& hands, const ForegroundConfig& config, std::vector<bool>& claimed,
                    ForegroundUpdate& out) {
  for (std::size_t ci = 0; ci < clusters.size() && !o.visible; ++ci) {
    const ObjectCluster& c = clusters[ci];
    if (claimed[ci] || c.box.extents.maxCoeff() > kMaxObjectExtentM || !hands.may_touch(c) || mostly_skin(*f.cloud, c.indices)) continue;
    if (!hands.touches(world_points(f, c))) continue;
    o.T = object_frame(c, o.T.linear());
    o.model = thinned(cluster_cloud(f, c, o.T.inverse()), config.model_voxel_m, config.max_model_points);
    o.visible = true;
    o.lost_in_hand = false;
    o.velocity.setZero();
    o.pixels = c.indices;
    claimed[ci] = true;
    out.claimed_clusters.push_back(ci);
  }
}

void reacquire(TouchedObject& o, const FrameView& f, const std::vector<ObjectCluster>& clusters,
               const ForegroundConfig& config, std::vector<bool>& claimed, ForegroundUpdate& out) {
  const Aabb model_box = bounds(posed_points(*o.model, Pose::Identity()));
  const double model_size = (model_box.max - model_box.min).norm();
  Registration best;
  std::size_t best_cluster = clusters.size();
  for (std::size_t ci = 0; ci < clusters.size(); ++ci) {
    const ObjectCluster& c = clusters[ci];
    if (claimed[ci] || (c.centroid - o.T.translation()).norm() > config.reacquire_radius_m) continue;
    if (c.box.extents.norm() > 2.5 * model_size) continue;
    const Cloud target = *thinned(cluster_cloud(f, c, Pose::Identity()), config.target_voxel_m, 20000);
    for (int turn = 0; turn < 4; ++turn) {
      Pose guess = o.T;
      guess.linear() = Eigen::AngleAxisd(turn * M_PI / 2, f.up_world).toRotationMatrix() * o.T.linear();
      guess.translation() = c.centroid;
      const Registration r = register_model(*o.model, target, guess, f.T_world_camera.translation(), config.registration, f.up_world);
      if (r.ok && r.inlier_fraction > best.inlier_fraction) best = r, best_cluster = ci;
    }
  }
  if (best_cluster == clusters.size()) return;
  o.T = best.T_world_object;
  o.visible = true;
  o.velocity.setZero();
  claimed[best_cluster] = true;
  out.claimed_clusters.push_back(best_cluster);
  o.pixels = clusters[best_cluster].indices;
}

}  // namespace scenewatch::foreground
