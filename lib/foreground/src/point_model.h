#pragma once
/// A foreground object's point model grown from its registered views: the sides a camera sees
/// only later (the back of a cup turned in a hand) join the model. Private to the foreground module.
#include <cstddef>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/foreground/registration.h"

namespace scenewatch::foreground {

struct ModelGrowth {
  double voxel_m = 0.005;            ///< one model point per voxel of this size
  std::size_t max_points = 4000;     ///< the model grows no further
  double max_rmse_m = 0.005;         ///< only views registered at least this well are merged...
  double min_inlier_fraction = 0.8;  ///< ...with at least this share of the model's visible side explained
};

/// True when a registration is good enough for its view to be merged into the model.
bool worth_merging(const Registration& r, const ModelGrowth& growth);

/// A copy of `model` (object frame) with the points of `view` (the frame's points of the object,
/// camera frame, with colour; skin-coloured points left out) added where they fill a voxel the
/// model does not yet hold, until the model holds max_points. `T_object_camera` maps the view
/// into the object frame. Returns `model` itself when nothing was added.
CloudPtr merged(const CloudPtr& model, const Cloud& cloud, const std::vector<int>& view,
                     const Pose& T_object_camera, const ModelGrowth& growth);

}  // namespace scenewatch::foreground
