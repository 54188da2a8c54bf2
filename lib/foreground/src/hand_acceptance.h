#pragma once
/// Step 5 of the hand detector (hand_detector.cpp): which candidates are hands, most confident
/// first, and the person grown from each accepted arm's base. Private to the foreground module.
#include <vector>

#include "hand_candidates.h"

namespace scenewatch::foreground {

/// The grid's labels once the hands are accepted.
struct AcceptedHands {
  std::vector<Candidate> hands;    ///< in the order accepted
  std::vector<AgentLabel> label;   ///< per grid cell
  std::vector<int> owner;          ///< per grid cell: the index in `hands` of its arm, -1 for none
};

/// Accepts hands from `candidates` (most confident first, as find_hand_candidates orders them).
AcceptedHands accept_hands(const Grid& g, std::vector<Candidate> candidates, const SupportCells& supports,
                           const HandConfig& config);

}  // namespace scenewatch::foreground
