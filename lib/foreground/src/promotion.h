#pragma once
/// Promotion: when a touched object (a candidate) becomes a foreground object, with its
/// OBJECT_PROMOTED event. Private to the foreground module.
#include "scenewatch/foreground/foreground_tracker.h"
#include "touched_object.h"

namespace scenewatch::foreground {

/// A touched object (a candidate: a hand touched it within touch_timeout_frames) is promoted
/// once it left its place: lifted off its support (a pick starts along the support's normal,
/// and while a cup's side wall still hides its old place none of that place is seen empty yet;
/// no contact is asked in this frame, as the hand that grasps a cup is often hidden behind it),
/// or moved or turned beyond the promotion thresholds with its old place seen empty.
/// On promotion: o.promoted and o.info.foreground set; the event, the old place's points (vacated)
/// and the id appended to `out`.
void promote_if_due(TouchedObject& o, const FrameView& f, const ForegroundConfig& config, ForegroundUpdate& out);

}  // namespace scenewatch::foreground
