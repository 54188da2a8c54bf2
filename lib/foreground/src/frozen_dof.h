#pragma once
/// The frozen-DoF check: a touched object's handling (from the first contact to release_frames
/// after the last) recorded frame by frame, and FROZEN_DOF_MOTION raised when a promoted object
/// moves in a degree of freedom that its earlier handlings never moved. Private to the foreground
/// module.
#include "scenewatch/foreground/foreground_tracker.h"
#include "touched_object.h"

namespace scenewatch::foreground {

/// The handling of one object in this frame: start, record, raise, end. `contact`: a hand touches
/// it now; T_support: the support frame (z along up) the handling's DoFs are measured in.
void handle(TouchedObject& o, bool contact, const FrameView& f, const Pose& T_support, const ForegroundConfig& config,
            ForegroundUpdate& out);

}  // namespace scenewatch::foreground
