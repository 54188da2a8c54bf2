// PCL's IterativeClosestPoint (by position; optionally with colour in a six-dimensional point
// representation), then the turn about the vertical searched by colour. The only PCL
// registration TU of the module.
#include "scenewatch/foreground/registration.h"

#include "nearest_search.h"

#include <pcl/console/print.h>
#include <pcl/search/kdtree.h>
#include <pcl/registration/correspondence_estimation.h>
#include <pcl/registration/icp.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace scenewatch::foreground {
namespace {

// x y z in metres, then r g b scaled so that a full colour difference weighs `weight` metres.
class XyzRgbRepresentation : public pcl::PointRepresentation<PointT> {
 public:
  explicit XyzRgbRepresentation(float weight) : weight_(weight) {
    nr_dimensions_ = 6;
    trivial_ = false;
  }
  void copyToFloatArray(const PointT& p, float* out) const override {
    out[0] = p.x;
    out[1] = p.y;
    out[2] = p.z;
    out[3] = weight_ * p.r / 255.0f;
    out[4] = weight_ * p.g / 255.0f;
    out[5] = weight_ * p.b / 255.0f;
  }

 private:
  float weight_;
};

// Model points whose outward direction (from the model's centroid) faces the camera: the side
// a camera can see of a compact object. A cheap stand-in for normals.
std::vector<int> facing_camera(const Cloud& posed, const Eigen::Vector3d& camera) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : posed.points) c += p.getVector3fMap().cast<double>();
  c /= std::max<std::size_t>(1, posed.size());
  std::vector<int> out;
  for (std::size_t i = 0; i < posed.size(); ++i) {
    const Eigen::Vector3d p = posed.points[i].getVector3fMap().cast<double>();
    if ((p - c).dot(camera - p) > -1e-3) out.push_back(static_cast<int>(i));
  }
  return out;
}

float colour_distance2(const PointT& a, const PointT& b) {
  const float dr = (a.r - b.r) / 255.0f, dg = (a.g - b.g) / 255.0f, db = (a.b - b.b) / 255.0f;
  return dr * dr + dg * dg + db * db;
}

// The turn about the vertical through the model's centre whose colours agree best with the frame.
Pose best_spin(const Cloud& model, const Pose& T, const pcl::search::KdTree<PointT>& tree, const Cloud& target,
               const Eigen::Vector3d& up, const RegistrationConfig& config) {
  if (config.spin_search_deg <= 0 || config.spin_step_deg <= 0) return T;
  const float gate2 = static_cast<float>(config.inlier_m * config.inlier_m);
  std::vector<int> k(1);
  std::vector<float> d2(1);
  // A turn's cost only grows point by point: once it reaches the best so far the turn has lost,
  // and the rest of its points need no search (the same answer at a fraction of the queries).
  auto cost = [&](const Pose& P, double bound) {
    double c = 0;
    for (const auto& p : model.points) {
      if (c >= bound) return c;
      PointT q = p;
      q.getVector3fMap() = (P * p.getVector3fMap().cast<double>()).cast<float>();
      if (tree.nearestKSearch(q, 1, k, d2) < 1 || d2[0] > gate2) {
        c += 1.0;  // nothing there: as bad as the worst colour
        continue;
      }
      c += std::min(1.0f, colour_distance2(p, target.points[static_cast<std::size_t>(k[0])]));
    }
    return c;
  };
  Pose best = T;
  double best_cost = cost(T, std::numeric_limits<double>::infinity());
  const Eigen::Vector3d centre = T.translation();
  for (double a = -config.spin_search_deg; a <= config.spin_search_deg + 1e-9; a += config.spin_step_deg) {
    if (std::abs(a) < 1e-9) continue;
    Pose spin = Pose::Identity();
    spin.linear() = Eigen::AngleAxisd(a * M_PI / 180.0, up.normalized()).toRotationMatrix();
    spin.translation() = centre - spin.linear() * centre;
    const Pose P = spin * T;
    const double c = cost(P, best_cost);
    if (c < best_cost) best_cost = c, best = P;
  }
  return best;
}

}  // namespace

Registration register_model(const Cloud& model, const Cloud& target, const Pose& T_guess,
                            const Eigen::Vector3d& camera_world, const RegistrationConfig& config,
                            const Eigen::Vector3d& up_world) {
  Registration r;
  r.T_world_object = T_guess;
  if (model.empty() || target.size() < config.min_inliers) return r;
  auto source = std::make_shared<Cloud>();
  pcl::transformPointCloud(model, *source, T_guess.matrix().cast<float>());
  auto target_ptr = std::make_shared<Cloud>(target);

  // A gate that finds too few correspondences is an answer here (the object is not there), not
  // an error for the console: PCL would print one per such frame.
  static const bool quiet = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    return true;
  }();
  (void)quiet;
  pcl::IterativeClosestPoint<PointT, PointT> icp;
  icp.setInputTarget(target_ptr);
  // Colour in the correspondences, when asked: the representation must reach the correspondence
  // search itself (ICP's own setter reaches a tree that PCL 1.13's ICP does not search with).
  if (config.colour_weight_m > 0) {
    auto estimation = std::make_shared<pcl::registration::CorrespondenceEstimation<PointT, PointT>>();
    estimation->setPointRepresentation(std::make_shared<const XyzRgbRepresentation>(static_cast<float>(config.colour_weight_m)));
    icp.setCorrespondenceEstimation(estimation);
  }
  // One k-d tree of the target serves ICP's correspondences, the spin search and the inlier count.
  auto tree = std::make_shared<NearestSearch>();
  tree->setInputCloud(target_ptr);
  if (config.colour_weight_m <= 0) icp.setSearchMethodTarget(tree, true);
  icp.setMaximumIterations(config.iterations);
  // An iteration that moves the model by less than converged_m and turns it by less than
  // converged_deg ends the gate (PCL's thresholds: squared translation, cosine of the angle).
  icp.setTransformationEpsilon(config.converged_m * config.converged_m);
  icp.setTransformationRotationEpsilon(std::cos(config.converged_deg * M_PI / 180.0));
  icp.setEuclideanFitnessEpsilon(1e-8);
  Eigen::Matrix4f total = Eigen::Matrix4f::Identity();
  Cloud aligned;
  // Coarse to fine: a wide gate catches a fast motion, a narrow one settles on the surface.
  for (double gate : {config.max_distance_m, config.max_distance_m / 2, config.max_distance_m / 4}) {
    icp.setInputSource(source);
    icp.setMaxCorrespondenceDistance(gate);
    icp.align(aligned);
    if (!icp.hasConverged()) break;
    total = icp.getFinalTransformation() * total;
    *source = aligned;
  }
  Pose delta(total.cast<double>());
  if (config.spin_search_deg > 0) {
    // ICP's turn about the vertical is left out (swing-twist decomposition, the twist dropped):
    // on a body of revolution it is noise, and the colour search below measures it instead.
    const Eigen::Vector3d u = up_world.normalized();
    const Eigen::Quaterniond q(delta.linear());
    const Eigen::Vector3d along = q.vec().dot(u) * u;
    Eigen::Quaterniond twist(q.w(), along.x(), along.y(), along.z());
    if (twist.norm() > 1e-9) {
      twist.normalize();
      const Eigen::Vector3d centre = T_guess.translation();
      const Eigen::Vector3d moved = delta * centre;
      delta.linear() = (q * twist.conjugate()).toRotationMatrix();
      delta.translation() = moved - delta.linear() * centre;
    }
  }
  r.T_world_object = best_spin(model, delta * T_guess, *tree, *target_ptr, up_world, config);
  pcl::transformPointCloud(model, *source, r.T_world_object.matrix().cast<float>());

  // How much of the visible side of the model the frame explains.
  const auto facing = facing_camera(*source, camera_world);
  std::vector<int> k(1);
  std::vector<float> d2(1);
  double sum2 = 0;
  const double gate2 = config.inlier_m * config.inlier_m;
  for (int i : facing) {
    if (tree->nearestKSearch(source->points[static_cast<std::size_t>(i)], 1, k, d2) < 1) continue;
    if (d2[0] > gate2) continue;
    ++r.inliers;
    sum2 += d2[0];
  }
  r.inlier_fraction = facing.empty() ? 0.0 : static_cast<double>(r.inliers) / facing.size();
  r.rmse_m = r.inliers ? std::sqrt(sum2 / r.inliers) : 0.0;
  r.ok = r.inliers >= config.min_inliers && r.inlier_fraction >= config.min_inlier_fraction;
  return r;
}

}  // namespace scenewatch::foreground
