#pragma once
// Cutting a part of a cluster at boundaries that its shape alone does not show: a book lying on a
// book, a thin box on a box (a depth step of 1-3 cm, depth_steps.h), and, when given, the colour
// edges between two objects of different print pressed together (colour_edges.h).
//
// On the part's pixels (organized clouds only), neighbours are one region unless a boundary lies
// between them. A cut needs a closed boundary: the regions must come apart in the image, so a
// stray step or a letter of a box's print that does not close around a region cuts nothing.
// Regions that came apart only through holes (a stereo camera's missing pixels, a shadow) have no
// boundary between them and join again where they touch in space. Two regions stay apart when
// both are as large as an object can be (min_part_size_m across, min_points points) and the
// boundary they share is at least min_part_size_m long; small regions join the neighbour they
// touch most. A boundary of colour edges alone must also run across the part, from outline to
// outline (both regions reach the part's outline): a picture printed inside a box's face is
// enclosed by its edges, two boxes pressed together are not.
#include <Eigen/Core>

#include <functional>
#include <vector>

#include "scenewatch/core/cloud.h"

namespace scenewatch::segmentation {

/// What lies between two neighbouring pixels (colour edges lie on pixels: EdgePixelTest).
enum class Boundary { kNone, kDepthStep };

/// The boundary between organized-cloud pixel `a` and pixel `a + offset` (offset 1: the right
/// neighbour, offset width: the one below); both pixels are valid points of the part.
using BoundaryTest = std::function<Boundary(int a, int offset)>;

/// Whether a pixel lies on a line of edges (colour_edges.h): it parts the pixels on its two sides.
using EdgePixelTest = std::function<bool(int i)>;

struct BoundaryCutParams {
  double min_part_size_m = 0.03;  ///< a region narrower than this is a fragment (convex_parts.h)
  int min_points = 100;           ///< a region with fewer points is a fragment
  double cluster_tolerance_m = 0.02;  ///< regions this close in space touch
};

/// The pieces of `part` (indices into the organized `cloud`, sorted) between depth steps
/// (`is_boundary`) and colour edges (`is_edge_pixel`, may be empty), each sorted; `{part}` when
/// no closed boundary separates two object-sized regions. A boundary's length is the spacing of the
/// pixels it runs between, across their rays from the sensor at `sensor_origin`.
std::vector<std::vector<int>> cut_at_boundaries(const Cloud& cloud, const std::vector<int>& part, const Eigen::Vector3d& sensor_origin,
                                                const BoundaryTest& is_boundary, const EdgePixelTest& is_edge_pixel,
                                                const BoundaryCutParams& params);

}  // namespace scenewatch::segmentation
