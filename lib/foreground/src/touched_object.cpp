// The tracker's events about a touched object (touched_object.h).
#include "touched_object.h"

#include "object_points.h"

namespace scenewatch::foreground {

Event event_for(const TouchedObject& o, EventKind kind, EventLevel level, const FrameView& f) {
  Event e;
  e.kind = kind;
  e.level = level;
  e.stamp_s = f.stamp_s;
  e.object_id = o.id;
  const auto pts = posed_points(*o.model, o.T);
  e.box_world = bounds(pts);
  e.centroid_world = e.box_world.center();
  e.evidence["frame"] = static_cast<double>(f.frame_index);
  return e;
}

}  // namespace scenewatch::foreground
