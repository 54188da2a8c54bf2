#pragma once
// Objects stacked flat on each other (books on books, a box on a book): one convex part whose faces
// parallel to the support lie at levels farther apart than the sensor's noise. Each level's face
// is the top of an object; the part's other pixels go to the face above them (issue 30, item 1:
// supports found inside a pile). Organized views only.
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::segmentation {

struct TerraceParams {
  SensorModel sensor;
  double sigma_factor = 3.0;     ///< levels apart by more than this many sigma of two depths
  double max_tilt_deg = 15.0;    ///< a face within this of the support's normal is level
  int min_points = 100;          ///< a face, and a piece, must have this many points
  double min_size_m = 0.03;      ///< and be this wide across
};

/// The part (organized cloud indices) cut at its levels, or unchanged. `n`, `d`: the support plane
/// (n . p + d = 0, n towards the sensor's side).
std::vector<std::vector<int>> split_at_terraces(const Cloud& cloud, std::vector<int> part, const Eigen::Vector3d& n, double d,
                                                const TerraceParams& params);

}  // namespace scenewatch::segmentation
