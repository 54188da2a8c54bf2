#pragma once
// Whether a cluster rests on its support, or crosses the support's plane (issue 30). An object
// standing on a table meets it at its foot: next to its lowest pixels lies the table's top, a
// surface that faces up. A chair's back or a person's body beside the table passes through the
// table's height: next to its lowest pixels above the table lies its own surface in the table's
// band, facing sideways, and it goes on below. Such a cluster is cut out of something standing on
// the floor by the prism over the table's hull, which the bands of such surfaces at the table's
// height stretch over them; it is not an object on the table.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch::pipeline {

struct SupportContact {
  std::size_t contacts = 0;  ///< band pixels next to the cluster's pixels whose normal could be measured
  std::size_t flat = 0;      ///< of them, facing within 45 degrees of the support's up
  /// Rests on the support: a quarter or more of the contacts face up, or there is no contact to
  /// judge by (a foot hidden behind the object, an unorganized cloud). A resting object's contacts
  /// are the support around its foot and the lowest strip of its own side, which lies in the
  /// band too; beyond that strip the patch reaches the support, so about half or more face up
  /// (hrt1's bin 47-67 %, the toy 63-100 %). A crossing surface's contacts are its own, facing
  /// sideways (hrt1's chair back 0-21 %, its seat 0-29 %). A quarter lies between the two; the
  /// tracker asks for it in consecutive sightings both ways.
  bool rests() const { return contacts == 0 || 4 * flat >= contacts; }
};

/// The contacts of a cluster (`indices` into the organized camera-frame `cloud`) with its support,
/// the plane up_camera . x + d_camera = 0 (up_camera a unit vector towards the objects): the
/// pixels 4-adjacent to the cluster's, outside it, within `band_m` of the plane and within
/// `link_m` of the cluster's pixel in 3D. Each contact's normal is measured on a `patch_m` patch
/// (at its depth, with the intrinsics `K`) beyond it, away from the cluster: the surface the
/// cluster meets there, not the cluster's own side. A patch that leaves the image or holds a
/// pixel without depth is not counted.
SupportContact support_contact(const std::vector<int>& indices, const Cloud& cloud, const Intrinsics& K,
                               const Eigen::Vector3d& up_camera, double d_camera, double band_m, double link_m,
                               double patch_m);

}  // namespace scenewatch::pipeline
