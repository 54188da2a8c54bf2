#pragma once
/// The hand detector's last step (hand_detector.cpp): its grid labels carried to the frame's full
/// resolution. Private to the foreground module.
#include "frame_grid.h"
#include "hand_acceptance.h"
#include "scenewatch/foreground/hand_detector.h"

namespace scenewatch::foreground {

/// Writes d.labels (sized to the frame already, all kNone), d.person_indices and, for each accepted
/// hand, one d.hands entry with its indices and tip_indices, all sorted: a full-resolution pixel
/// takes its grid cell's label when its depth is within depth_jump_m of the cell's sample.
void upsample_labels(const Cloud& organized, const Grid& g, const AcceptedHands& accepted, float depth_jump_m,
                     HandDetection& d);

}  // namespace scenewatch::foreground
