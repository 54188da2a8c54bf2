// The events of one frame (frame_events.h).
#include "frame_events.h"

#include <algorithm>

#include "scenewatch/change/objects.h"

namespace scenewatch::pipeline {

std::vector<Event> frame_events(EventFusion& fusion, const FrameResult& result, const ChangeOutcome& changed,
                                const std::vector<Aabb>& quiet, double stamp_s, const std::vector<TrackedObject>& known,
                                std::uint32_t camera) {
  auto explained = [&](const Aabb& box) {
    return std::any_of(quiet.begin(), quiet.end(), [&](const Aabb& q) { return q.overlaps(box); });
  };
  std::vector<Event> geometric;
  std::vector<Aabb> boxes;  // both places of a move
  for (const auto& c : changed.confirmed) {
    Event e = change::to_event(c);
    if (explained(e.box_world)) continue;
    e.stamp_s = stamp_s;
    geometric.push_back(std::move(e));
    if (c.before) boxes.push_back(c.before->box_world);
    if (c.after) boxes.push_back(c.after->box_world);
  }
  std::vector<Event> appearance;
  if (result.surprise) {
    for (const auto& e : result.surprise->events)
      if (!explained(e.box_world)) appearance.push_back(e);
  }
  const bool familiar = result.surprise && result.surprise->familiar_view;
  return fusion.update(appearance, changed.pending, std::move(geometric), std::move(boxes), familiar, known, result.objects,
                       camera);
}

}  // namespace scenewatch::pipeline
