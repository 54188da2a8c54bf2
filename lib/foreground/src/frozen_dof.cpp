// The frozen-DoF check (frozen_dof.h): a tracked object's handling frame by frame and the
// FROZEN_DOF_MOTION event when it moves in a DoF that its earlier handlings never moved.
#include "frozen_dof.h"

#include <sstream>
#include <string>

namespace scenewatch::foreground {
namespace {

// FROZEN_DOF_MOTION, once per handling, when DoFs the earlier handlings never moved (o.free) move
// now: the event names them all and scores the one that moved most beyond its threshold.
void raise_frozen(TouchedObject& o, const DofFlags& fresh, const FrameView& f, const ForegroundConfig& config,
                  ForegroundUpdate& out) {
  const Handling now = o.handling->handling(0.0, config.dof);
  int worst = -1;
  double worst_ratio = 0;
  std::string named;
  for (int k = 0; k < kDofCount; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (!fresh[ks] || o.free[ks]) continue;
    const double ratio = now.range[ks] / (k < 3 ? config.dof.translation_m : config.dof.rotation_deg);
    named += (named.empty() ? "" : ", ") + std::string(to_string(static_cast<Dof>(k)));
    if (ratio > worst_ratio) worst_ratio = ratio, worst = k;
  }
  if (worst < 0) return;
  Event e = event_for(o, EventKind::kFrozenDofMotion, EventLevel::kImplausibility, f);
  const auto ws = static_cast<std::size_t>(worst);
  e.score = worst_ratio;
  std::ostringstream detail;
  detail.precision(3);
  detail << "motion in frozen DoF " << to_string(static_cast<Dof>(worst)) << ": " << now.range[ws]
         << (worst < 3 ? " m" : " deg") << " (frozen DoFs that moved: " << named << ")";
  e.detail = detail.str();
  e.evidence["dof"] = worst;
  e.evidence["magnitude"] = now.range[ws];
  e.evidence["handling"] = static_cast<double>(o.handlings.size());
  for (int k = 0; k < kDofCount; ++k) e.evidence[std::string("range_") + to_string(static_cast<Dof>(k))] = now.range[static_cast<std::size_t>(k)];
  out.events.push_back(std::move(e));
  o.handling_raised = true;
}

}  // namespace

void handle(TouchedObject& o, bool contact, const FrameView& f, const Pose& T_support, const ForegroundConfig& config,
            ForegroundUpdate& out) {
  if (contact) {
    o.last_contact = f.frame_index;
    if (!o.handling) {
      o.handling.emplace(T_support, o.T, f.stamp_s);
      o.handling_raised = false;
    }
  }
  if (!o.handling) return;
  if (o.visible) {
    const DofFlags fresh = o.handling->add(o.T, config.dof);
    const bool learning = o.handlings.empty();
    if (o.promoted && !learning && !o.handling_raised) raise_frozen(o, fresh, f, config, out);
  }
  if (f.frame_index - o.last_contact > static_cast<std::uint64_t>(config.release_frames)) {
    const Handling h = o.handling->handling(f.stamp_s, config.dof);
    if (o.promoted) {
      for (std::size_t k = 0; k < h.moved.size(); ++k) o.free[k] = o.free[k] || h.moved[k];
      o.handlings.push_back(h);
    }
    o.handling.reset();
  }
}

}  // namespace scenewatch::foreground
