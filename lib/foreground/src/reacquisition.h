#pragma once
/// Reacquisition: a promoted object whose track was lost, found again among the frame's clusters,
/// either in the hand that held it (its model re-seeded) or near its last place (registered).
/// Private to the foreground module.
#include <vector>

#include "hand_contact.h"
#include "scenewatch/foreground/foreground_tracker.h"
#include "touched_object.h"

namespace scenewatch::foreground {

/// What a hand holds when the track of the object it held was lost is that object (a plush toy
/// deforms and turns faster than registration follows at 10 frames per second): the first
/// unclaimed, object-sized, not mostly skin cluster a hand touches becomes its model, seen from
/// here. Sets o.visible when it does, claims the cluster in `claimed` and `out`.
void reseed_in_hand(TouchedObject& o, const FrameView& f, const std::vector<ObjectCluster>& clusters,
                    const HandContact& hands, const ForegroundConfig& config, std::vector<bool>& claimed,
                    ForegroundUpdate& out);

/// A lost foreground object among the frame's unclaimed clusters near its last place: its model
/// registered to each (four turns about up), the best inlier fraction wins. Sets o.visible when
/// found, claims the cluster in `claimed` and `out`.
void reacquire(TouchedObject& o, const FrameView& f, const std::vector<ObjectCluster>& clusters,
               const ForegroundConfig& config, std::vector<bool>& claimed, ForegroundUpdate& out);

}  // namespace scenewatch::foreground
