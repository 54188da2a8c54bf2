// Support reasoning: see support.h. Heights are along the plane's normal; an object resting on
// another starts where that one ends, over its footprint.
#include "support.h"

#include "footprint.h"

namespace scenewatch::segmentation {

void assign_supports(const Cloud& cloud, std::vector<ObjectCluster>& objects, const std::vector<Plane>& planes,
                     const SupportParams& params) {
  std::vector<Footprint> feet;
  feet.reserve(objects.size());
  for (const auto& o : objects) feet.push_back(footprint(cloud, o.indices, planes[o.plane_id].normal));
  for (std::size_t a = 0; a < objects.size(); ++a) {
    ObjectCluster& upper = objects[a];
    upper.supported_by = -1;
    const double plane_height = -planes[upper.plane_id].d;  // n.p + d = 0 on the plane
    if (feet[a].low - plane_height <= params.min_object_height_m + params.margin_m) continue;
    double best_top = -1e300;
    for (std::size_t b = 0; b < objects.size(); ++b) {
      if (b == a || objects[b].plane_id != upper.plane_id) continue;
      const Footprint& lower = feet[b];
      if (feet[a].low < lower.high - params.margin_m || lower.high <= best_top) continue;
      if (std::max(share_inside(feet[a], lower), share_inside(lower, feet[a])) < params.min_overlap) continue;
      best_top = lower.high;
      upper.supported_by = static_cast<int>(b);
    }
  }
}

}  // namespace scenewatch::segmentation
