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
  /// Rests on the support: half or more of the contacts face up, or there is no contact to judge
  /// by (a foot hidden behind the object or by its neighbours, an unorganized cloud). A resting
  /// object meets the support's top beyond its foot (hrt1's bin 94-99 % of its contacts face up,
  /// the toy 94-100 %); a surface that runs on through the support's height meets only itself in
  /// the band, facing sideways (hrt1's chair back 0-23 %, the rim of its seat 0-25 %).
  bool rests() const { return contacts == 0 || 2 * flat >= contacts; }
};

/// The contacts of a cluster (`indices` into the organized camera-frame `cloud`) with its support,
/// the plane up_camera . x + d_camera = 0 (up_camera a unit vector towards the objects): the
/// pixels 4-adjacent to the cluster's, outside it, within `band_m` of the plane and within
/// `link_m` of the cluster's pixel in 3D. Each contact's normal is measured on a `patch_m` patch
/// (at its depth, with the intrinsics `K`) one patch beyond it, away from the cluster: the surface
/// the cluster meets there, not the strip of its own side that lies in the band too. A patch that
/// leaves the image, holds a pixel without depth or leaves the band is not counted: so what is
/// seen is a surface that lies in the support's band beside the foot, sideways (a chair's curved
/// back or the rim of its seat, meeting the table's height at a slant), not a post that crosses
/// it upright (its side leaves the band within a patch).
SupportContact support_contact(const std::vector<int>& indices, const Cloud& cloud, const Intrinsics& K,
                               const Eigen::Vector3d& up_camera, double d_camera, double band_m, double link_m,
                               double patch_m);

}  // namespace scenewatch::pipeline
