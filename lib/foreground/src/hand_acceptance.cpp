// Step 5 of the hand detector (hand_acceptance.h): most confident first, a candidate inside an
// accepted hand's person is that person (face, legs), one beside an accepted arm joins it; the
// person is grown from the arm's base (never from the hand, which may hold an object) through
// depth-continuous cells off the planes, within person_max_extent_m of the entry,
// person_max_depth_offset_m of its depth, and not back towards the hand.
#include "hand_acceptance.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace scenewatch::foreground {
namespace {

/// A candidate with more than this fraction of its cells in an accepted hand's person is part of
/// that person, unless it is a clear second arm (this long and this elongated).
constexpr double kInPersonFraction = 0.3;
constexpr double kSecondArmMinLengthM = 0.3;
constexpr double kSecondArmMinElongation = 4.0;
/// The person's pixels are at least the entry's distance from the hand, less this.
constexpr double kBodyBehindEntryM = 0.15;

// The arm a candidate lies beside (a 4-neighbour of one of its cells is that arm's), or -1.
int arm_beside(const Grid& g, const std::vector<int>& cells, const std::vector<int>& owner) {
  int touching = -1;
  for (int i : cells) {
    const int cu = i % g.w, cv = i / g.w;
    for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int nu = cu + du, nv = cv + dv;
      if (nu < 0 || nv < 0 || nu >= g.w || nv >= g.h) continue;
      if (owner[nv * g.w + nu] >= 0) touching = owner[nv * g.w + nu];
    }
    if (touching >= 0) break;
  }
  return touching;
}

// The person of an accepted arm `cand`, grown from its base. The seeds (arm cells) come back in
// the growth; only unlabelled cells become the person. Cells of other skin components may join:
// a face or bare legs are the person's.
std::vector<int> grow_person(const Grid& g, const Candidate& cand, const AcceptedHands& a, const SupportCells& supports,
                             const HandConfig& config, std::vector<int>& scratch, int id) {
  const float jump = static_cast<float>(config.depth_jump_m);
  const std::vector<AgentLabel>& grid_label = a.label;
  const double min_tip_distance = std::max(config.tip_clearance_m, (cand.entry_point - cand.tip).norm() - kBodyBehindEntryM);
  return grow(g, cand.base_cells, jump, scratch, id, [&](int i) {
    if (grid_label[i] == AgentLabel::kHand || grid_label[i] == AgentLabel::kArm || supports.near_support.data[i]) return false;
    // Nor onto the table's plane beyond the patches found: where the plane fit missed part of
    // the table (a missed body pixel is better than the table as a person).
    if (supports.plane_distance[i] < supports.plane_config.tolerance_at(g.p[i].z())) return false;
    if (g.p[i].z() > config.person_max_range_m) return false;
    // Depth edges are smeared (mixed pixels ramp from the body to the wall behind it): the
    // body stays within this depth of the arm's entry.
    if (std::abs(g.p[i].z() - cand.entry_point.z()) > config.person_max_depth_offset_m) return false;
    const Eigen::Vector3d q = g.p[i].cast<double>();
    if ((q - cand.entry_point).norm() > config.person_max_extent_m) return false;
    // The body lies beyond the arm's entry as seen from the hand: not back towards the hand
    // along a wall or a table edge.
    for (const Candidate& hand : a.hands) {
      if ((q - hand.tip).norm() < config.tip_clearance_m) return false;
    }
    return (q - cand.tip).norm() >= min_tip_distance;
  });
}

}  // namespace

AcceptedHands accept_hands(const Grid& g, std::vector<Candidate> candidates, const SupportCells& supports,
                           const HandConfig& config) {
  // Most confident first: accept a hand, grow its person. A later candidate inside that person
  // (a face, skin-coloured trousers) is the person, unless it is clearly a second arm; one next to
  // an accepted hand (a skin-coloured part of what it holds) is nothing.
  const std::size_t n = g.p.size();
  AcceptedHands a;
  std::vector<AgentLabel>& grid_label = a.label;
  std::vector<int>& owner = a.owner;
  grid_label.assign(n, AgentLabel::kNone);
  owner.assign(n, -1);
  std::vector<int> scratch(n, 0);
  int scratch_id = 0;
  for (Candidate& cand : candidates) {
    std::size_t in_person = 0;
    for (int i : cand.cells) in_person += grid_label[i] == AgentLabel::kPerson;
    const bool second_arm = cand.length_m >= kSecondArmMinLengthM && cand.elongation >= kSecondArmMinElongation;
    if (in_person > kInPersonFraction * cand.cells.size() && !second_arm) {
      for (int i : cand.cells) grid_label[i] = AgentLabel::kPerson;
      continue;
    }
    bool at_a_hand = false;
    for (const Candidate& hand : a.hands) {
      if ((cand.tip - hand.tip).norm() < config.tip_clearance_m + config.tip_length_m) at_a_hand = true;
    }
    if (at_a_hand) continue;
    // A piece beside an accepted arm is more of that arm (split off by a depth jump along a
    // silhouette, or by colour and depth that do not quite line up).
    const int touching = arm_beside(g, cand.cells, owner);
    if (touching >= 0) {
      for (int i : cand.cells) {
        if (grid_label[i] == AgentLabel::kNone) grid_label[i] = AgentLabel::kArm, owner[i] = touching;
      }
      continue;
    }
    const int index = static_cast<int>(a.hands.size());
    for (int i : cand.cells) grid_label[i] = AgentLabel::kArm, owner[i] = index;
    for (int i : cand.tip_cells) grid_label[i] = AgentLabel::kHand;
    const std::vector<int> body = grow_person(g, cand, a, supports, config, scratch, ++scratch_id);
    for (int i : body) {
      if (grid_label[i] == AgentLabel::kNone) grid_label[i] = AgentLabel::kPerson;
    }
    a.hands.push_back(std::move(cand));
  }
  return a;
}

}  // namespace scenewatch::foreground
