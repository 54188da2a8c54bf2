// The object tracker's input from one frame (object_observations.h).
#include "object_observations.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "foreground_stage.h"
#include "support_contact.h"

namespace scenewatch::pipeline {

namespace {

constexpr std::size_t kSamplesPerObject = 200;
constexpr std::size_t kPointsPerObject = 4000;  // kept per object for the ontology's describe()

// World sample points of each cluster, for the tracker's free-space evidence; clusters the
// foreground claimed are left out.
std::vector<TrackerObservation> tracker_observations(const std::vector<ObjectCluster>& objects, const Cloud& cloud,
                                                     const Pose& T, const std::vector<std::size_t>& claimed) {
  std::vector<TrackerObservation> observations;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (std::find(claimed.begin(), claimed.end(), i) != claimed.end()) continue;
    TrackerObservation o;
    const auto& idx = objects[i].indices;
    const std::size_t step = std::max<std::size_t>(1, idx.size() / kSamplesPerObject);
    for (std::size_t k = 0; k < idx.size(); k += step)
      o.samples.push_back(T * cloud.points[static_cast<std::size_t>(idx[k])].getVector3fMap().cast<double>());
    auto points = std::make_shared<std::vector<Eigen::Vector3d>>();
    const std::size_t every = std::max<std::size_t>(1, idx.size() / kPointsPerObject);
    for (std::size_t k = 0; k < idx.size(); k += every)
      points->push_back(T * cloud.points[static_cast<std::size_t>(idx[k])].getVector3fMap().cast<double>());
    o.points = std::move(points);
    o.cluster = objects[i];
    o.range_m = (objects[i].centroid - T.translation()).norm();
    observations.push_back(std::move(o));
  }
  return observations;
}

// A box that lies for the most part (half its volume or more) in one of the frame's hands or arms,
// or in the person's body, each grown by `margin_m`: a finger, a sleeve, a shirt or a leg the
// detector left out, not an object the hand reaches for. With a level `up` that lies along an axis
// of the world, the body also goes on downward, as a standing person does: a box that reaches up
// to the body's underside and lies mostly in the column below it (trousers and hips, which the
// skin and clothing colours did not take in; hrt1's pick_toy_2 listed them from its first frame
// to its 31st) is the person too. An object on the table under a reaching arm stops short of the
// body's underside, and is not taken.
bool touches_person(const Aabb& box, const HandsSeen& hands, double margin_m, const std::optional<Eigen::Vector3d>& up) {
  const double volume = (box.max - box.min).cwiseMax(1e-6).prod();
  const auto mostly_in = [&](const Aabb& agent) {
    const Eigen::Vector3d lo = (agent.min.array() - margin_m).max(box.min.array());
    const Eigen::Vector3d hi = (agent.max.array() + margin_m).min(box.max.array());
    return (hi.array() > lo.array()).all() && (hi - lo).prod() >= 0.5 * volume;
  };
  for (const auto& h : hands.hands)
    if (mostly_in(h.box_world)) return true;
  if (!hands.person_box_world) return false;
  const Aabb& body = *hands.person_box_world;
  if (mostly_in(body)) return true;
  int axis = -1;
  if (up) up->cwiseAbs().maxCoeff(&axis);
  if (axis < 0 || std::abs((*up)(axis)) < std::cos(M_PI / 12)) return false;  // no world axis within 15 degrees of up
  const bool z_up = (*up)(axis) > 0;
  // The body's underside along up, and whether the box reaches it from below.
  const double underside = z_up ? body.min(axis) : body.max(axis);
  const bool reaches = z_up ? box.max(axis) >= underside - margin_m && box.min(axis) < underside
                            : box.min(axis) <= underside + margin_m && box.max(axis) > underside;
  if (!reaches) return false;
  Aabb column = body;
  if (z_up) column.min(axis) = -std::numeric_limits<double>::infinity();
  else column.max(axis) = std::numeric_limits<double>::infinity();
  return mostly_in(column);
}

// Whether a cluster rests on its plane (support_contact.h), judged in the camera's frame.
bool rests_on_its_plane(const ObjectCluster& cluster, const std::vector<Plane>& planes, const Cloud& cloud, const Pose& T,
                        const Intrinsics& K, const segmentation::Config& seg) {
  const auto plane = std::find_if(planes.begin(), planes.end(), [&](const Plane& p) { return p.id == cluster.plane_id; });
  if (plane == planes.end() || cluster.supported_by >= 0) return true;  // on another object: its own contacts
  const Eigen::Vector3d up = plane->normal_towards(T.translation());
  const double d = plane->normal.normalized().dot(up) > 0 ? plane->d / plane->normal.norm() : -plane->d / plane->normal.norm();
  // In the camera's frame: up . (R x + t) + d = (R^T up) . x + (up . t + d).
  const SupportContact c = support_contact(cluster.indices, cloud, K, T.linear().transpose() * up, up.dot(T.translation()) + d,
                                           seg.plane_distance_m, seg.cluster_tolerance_m, seg.patch_size_m);
  return c.rests();
}

// Objects stand on tables, shelves and floors, not on walls: the clusters whose supporting plane
// faces more than 45 degrees away from the world's up (up_direction's own bound) are a wall's
// relief (a whiteboard, a poster, a socket), not objects to list. Their space is never seen free,
// so the list would only grow: hrt1's pick_toy_2 ended with 60 objects, most of them pieces of
// the wall behind the table.
void keep_on_level_supports(std::vector<TrackerObservation>& observations, const std::vector<Plane>& planes,
                            const Eigen::Vector3d& up, const Eigen::Vector3d& camera) {
  const auto level = [&](int plane_id) {
    for (const auto& p : planes)
      if (p.id == plane_id) return faces_within_45_degrees(p, camera, up);
    return true;  // no plane to judge by
  };
  observations.erase(std::remove_if(observations.begin(), observations.end(),
                                    [&](const TrackerObservation& o) { return !level(o.cluster.plane_id); }),
                     observations.end());
}

}  // namespace

std::vector<TrackerObservation> tracker_input(const FrameResult& result, const Cloud& cloud, const Pose& T,
                                              const std::optional<Intrinsics>& K, const std::vector<std::size_t>& claimed,
                                              const HandsSeen& hands, std::uint64_t frame_index, const Config& config) {
  const std::optional<Eigen::Vector3d>& configured_up = config.segmentation.up;
  std::vector<TrackerObservation> observations = tracker_observations(result.objects, cloud, T, claimed);
  // Only with an up to trust: a largest plane taken for want of a level one may be a wall.
  const auto up = level_up(configured_up, result.planes, T);
  for (auto& o : observations) {
    o.resolution_m = std::max(config.segmentation.voxel_size_m, 2 * config.sensor.sigma_z(o.range_m));
    if (hands.frame_index == frame_index) {
      o.touches_person = touches_person(o.cluster.box.aabb(), hands, config.segmentation.cluster_tolerance_m, up);
    }
  }
  if (up) keep_on_level_supports(observations, result.planes, *up, T.translation());
  if (K)
    for (auto& o : observations) o.rests = rests_on_its_plane(o.cluster, result.planes, cloud, T, *K, config.segmentation);
  return observations;
}

double free_fraction(const background::OccupancyMap& map, const std::vector<Eigen::Vector3d>& pts) {
  if (pts.empty()) return 0.0;
  std::size_t n = 0;
  for (const auto& p : pts) n += (map.freed_by_last_insert(p) || map.query(p) == background::Occupancy::kFree) ? 1 : 0;
  return static_cast<double>(n) / pts.size();
}

namespace {

// The share of `points` (world) that project into the organized frame's image onto a pixel whose
// depth lies within the sensor's 3 sigma plus a voxel of theirs and that `counts` accepts.
template <typename Counts>
double share_in_place(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                      const std::vector<Eigen::Vector3d>& points, const Counts& counts) {
  if (!K || cloud.height <= 1 || points.empty() || static_cast<int>(cloud.width) != K->width) return 0.0;
  const Pose T_camera_world = T.inverse();
  std::size_t n = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d q = T_camera_world * p;
    if (q.z() <= 0) continue;
    const long u = std::lround(K->fx * q.x() / q.z() + K->cx), v = std::lround(K->fy * q.y() / q.z() + K->cy);
    if (u < 0 || v < 0 || u >= static_cast<long>(cloud.width) || v >= static_cast<long>(cloud.height)) continue;
    const std::size_t i = static_cast<std::size_t>(v) * cloud.width + static_cast<std::size_t>(u);
    const PointT& f = cloud.points[i];
    if (!is_valid(f)) continue;
    n += std::abs(f.z - q.z()) < 3 * config.sensor.sigma_z(q.z()) + config.segmentation.voxel_size_m && counts(i);
  }
  return static_cast<double>(n) / static_cast<double>(points.size());
}

}  // namespace

double seen_in_place(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                     const std::vector<Eigen::Vector3d>& points) {
  return share_in_place(cloud, T, K, config, points, [](std::size_t) { return true; });
}

double seen_on_person(const Cloud& cloud, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                      const foreground::HandDetection& agents, const std::vector<Eigen::Vector3d>& points) {
  if (agents.labels.size() != cloud.points.size()) return 0.0;
  return share_in_place(cloud, T, K, config, points,
                        [&](std::size_t i) { return agents.labels[i] == foreground::AgentLabel::kPerson; });
}

}  // namespace scenewatch::pipeline
