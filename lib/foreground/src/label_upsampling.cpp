// Grid labels to full resolution (label_upsampling.h): each step x step block takes its sample's
// label where its depth is continuous with the sample's.
#include "label_upsampling.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::foreground {

void upsample_labels(const Cloud& organized, const Grid& g, const AcceptedHands& accepted, float depth_jump_m,
                     HandDetection& d) {
  const float jump = depth_jump_m;
  const std::vector<AgentLabel>& grid_label = accepted.label;
  const std::vector<int>& owner = accepted.owner;
  d.hands.resize(accepted.hands.size());
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      const int cell = gv * g.w + gu;
      const AgentLabel label = grid_label[cell];
      if (label == AgentLabel::kNone) continue;
      const float z = g.p[cell].z();
      for (int v = gv * g.step; v < std::min(g.full_h, (gv + 1) * g.step); ++v) {
        for (int u = gu * g.step; u < std::min(g.full_w, (gu + 1) * g.step); ++u) {
          const int i = v * g.full_w + u;
          const PointT& pt = organized.points[i];
          if (!is_valid(pt) || std::abs(pt.z - z) >= jump) continue;
          d.labels[i] = label;
          if (label == AgentLabel::kPerson) {
            d.person_indices.push_back(i);
          } else {
            Hand& hand = d.hands[owner[cell]];
            hand.indices.push_back(i);
            if (label == AgentLabel::kHand) hand.tip_indices.push_back(i);
          }
        }
      }
    }
  }
  std::sort(d.person_indices.begin(), d.person_indices.end());
  for (Hand& hand : d.hands) {
    std::sort(hand.indices.begin(), hand.indices.end());
    std::sort(hand.tip_indices.begin(), hand.tip_indices.end());
  }
}

}  // namespace scenewatch::foreground
