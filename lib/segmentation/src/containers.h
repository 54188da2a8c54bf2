#pragma once
// The inside of a round container (a mug, a bowl, a pot) is concave, so the split at concave
// creases cuts it from the outer wall, and a tall rim can hide the connection altogether. Seen
// from above, both pieces lie on one circle: the outer wall is an arc of it, and the inside lies
// within it. Two pieces at the same heights where one is such an arc and the other lies inside
// its circle are one object. (A thing standing inside a bowl joins the bowl: rare on a table.)
#include <vector>

#include "piece.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::segmentation {

struct ContainerParams {
  double min_radius_m = 0.02;       ///< smaller arcs are noise on an edge
  double max_radius_m = 0.2;        ///< larger: a flat face, not a container wall
  double max_rms_ratio = 0.06;       ///< circle-fit residual over the radius (walls spread by depth noise, 3 mm at 1 m)
  double wall_margin_m = 0.01;      ///< the inside may reach this far beyond the circle
  double min_inside_share = 0.8;    ///< of the other piece's points within the circle
  double stacking_margin_m = 0.02;  ///< one piece above the other's top: stacked, not nested
};

/// Joins pieces of one round container (pieces on the same plane; planes by id).
std::vector<Piece> join_container_pieces(const Cloud& cloud, std::vector<Piece> pieces, const std::vector<Plane>& planes,
                                         const ContainerParams& params);

}  // namespace scenewatch::segmentation
