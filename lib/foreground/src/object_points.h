#pragma once
/// Points of touched objects and of the frame's clusters, in the world or an object's frame: what
/// the foreground tracker's parts (tracking, promotion, reacquisition) share. Private to the
/// foreground module.
#include <cstddef>
#include <vector>

#include "scenewatch/foreground/foreground_tracker.h"

namespace scenewatch::foreground {

/// A point of the cloud, mapped by T.
inline Eigen::Vector3d world(const PointT& p, const Pose& T) { return T * p.getVector3fMap().cast<double>(); }

/// The box around the points.
Aabb bounds(const std::vector<Eigen::Vector3d>& pts);

/// Keeps one point per voxel (the first), at most `max_points` (voxel <= 0: every point).
CloudPtr thinned(const Cloud& in, double voxel, std::size_t max_points);

/// The world box around a cluster's oriented box (clusters come in the world frame).
Aabb world_box(const ObjectCluster& c);

/// A cluster's points (world frame).
std::vector<Eigen::Vector3d> world_points(const FrameView& f, const ObjectCluster& c);

/// A cluster's points with their colour, in the frame T_frame_world maps the world into (the world
/// itself for a registration target, an object's frame for its model).
Cloud cluster_cloud(const FrameView& f, const ObjectCluster& c, const Pose& T_frame_world);

/// The frame of an object seen as cluster c, turned as R: origin at the cluster's centroid.
Pose object_frame(const ObjectCluster& c, const Eigen::Matrix3d& R);

/// A model's points placed by T.
std::vector<Eigen::Vector3d> posed_points(const Cloud& model, const Pose& T);

}  // namespace scenewatch::foreground
