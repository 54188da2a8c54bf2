#pragma once
/// A touched object as the foreground tracker keeps it: a candidate (a hand touched it) until it
/// is promoted, then a foreground object, tracked, handled and reacquired. Shared by the tracker's
/// parts (foreground_tracker.cpp, promotion.h, reacquisition.h, frozen_dof.h). Private to the
/// foreground module.
#include <cstdint>
#include <optional>
#include <vector>

#include "scenewatch/foreground/foreground_tracker.h"

namespace scenewatch::foreground {

struct TouchedObject {
  std::uint64_t id = 0;
  bool promoted = false;
  CloudPtr model;                       // object frame, with colour
  Pose T = Pose::Identity();            // T_world_object now
  Pose T_home = Pose::Identity();       // where it stood when first touched
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // per frame
  bool visible = true;
  bool in_hand = false;
  bool lost_in_hand = false;            // its track was lost while a hand held it
  bool piece = false;                   // a candidate found to be a piece of a foreground object
  CloudPtr sparse;                      // the model thinned for registration
  const Cloud* sparse_of = nullptr;     // the model it was thinned from
  std::vector<int> pixels;              // this frame
  std::optional<HandlingRecorder> handling;
  bool handling_raised = false;
  std::uint64_t last_contact = 0;
  std::vector<Handling> handlings;
  DofFlags free{};
  TrackedObject info;                   // what GetObjects shows
};

/// An event about the object in this frame: its box and centroid where the model stands now.
Event event_for(const TouchedObject& o, EventKind kind, EventLevel level, const FrameView& f);

}  // namespace scenewatch::foreground
