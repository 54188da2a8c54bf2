#include "next_best_view_call.h"

#include <cmath>
#include <cstdio>

#include "class_records.h"
#include "proto_convert.h"
#include "scenewatch/pipeline/covariance_view_request.h"
#include "scenewatch/pipeline/object_view_request.h"
#include "scenewatch/planning/covariance_view.h"
#include "scenewatch/planning/next_best_view.h"

namespace scenewatch::service {

namespace {

// Largest dense copy of the map one call may ask for: 2^24 voxels (16 MB), a 5 m cube at 2 cm.
constexpr std::size_t kMaxPlanningVoxels = std::size_t{1} << 24;

// The box of a pending change, or why there is none: what became of an id no longer pending.
Result<Aabb> pending_box(const pipeline::WorkingMemory& memory, std::uint64_t id) {
  const std::string name = "pending_id: pending change " + std::to_string(id);
  if (id == 0) return invalid_argument("pending_id: 0 names no pending change (ids count from 1; GetPendingChanges lists them)");
  const auto snapshot = memory.snapshot();
  for (const auto& seen : snapshot->pending) {
    if (seen.change.id == id) return seen.change.box_world;
  }
  // The snapshot was published after the frame's events were logged: an id it no longer lists
  // is in the log already if an event confirmed it.
  if (const auto event = memory.event_of_pending(id)) {
    return not_found(name + " is no longer pending: it was confirmed as event " + std::to_string(*event) +
                     " (target that with event_id " + std::to_string(*event) + ")");
  }
  if (id <= memory.last_pending_id()) {
    return not_found(name + " is no longer pending, and no event in the log names it: it was dropped (not seen again, or "
                            "forgotten by a Reset or a load) or confirmed as a piece of a change told before; "
                            "GetPendingChanges lists those pending now");
  }
  return not_found(name + " was never given (the last id given is " + std::to_string(memory.last_pending_id()) +
                   "; GetPendingChanges lists those pending now)");
}

// The request's target from the message's, and a sentence saying what it is.
Result<planning::NextBestViewRequest> target_request(pipeline::WorkingMemory& memory, const proto::NextBestView& msg,
                                                     ontology::ClassCatalog* classes, std::string& description) {
  switch (msg.target_case()) {
    case proto::NextBestView::kObjectId: {
      auto r = pipeline::object_view_request(memory, msg.object_id(), classes,
                                             classes ? recorder(*classes) : pipeline::DescribedCallback{});
      if (!r) return r.error();
      description = std::move(r->target_description);
      return std::move(r->request);
    }
    case proto::NextBestView::kEventId: {
      const auto events = memory.events_since(msg.event_id() == 0 ? 0 : msg.event_id() - 1, 1);
      if (events.empty() || events.front().id != msg.event_id()) {
        return not_found("event_id: no event " + std::to_string(msg.event_id()) + " in the log");
      }
      description = "event " + std::to_string(msg.event_id()) + "'s box, grown by 4 cm";
      return planning::confirm_event_request(events.front().box_world);
    }
    case proto::NextBestView::kPendingId: {
      auto box = pending_box(memory, msg.pending_id());
      if (!box) return box.error();
      description = "pending change " + std::to_string(msg.pending_id()) + "'s box, grown by 4 cm";
      return planning::confirm_event_request(*box);
    }
    case proto::NextBestView::kBox: {
      auto box = convert::decode_box(msg.box(), "box");
      if (!box) return box.error();
      description = "the box given";
      return planning::complete_object_request(*box, 0.0);
    }
    case proto::NextBestView::kWorkspace: {
      const auto snapshot = memory.snapshot();
      if (snapshot->objects.empty()) return not_found("workspace: no tracked objects yet");
      Aabb all = snapshot->objects.front().cluster.box.aabb();
      for (const auto& o : snapshot->objects) all = all.united(o.cluster.box.aabb());
      description = "the box of every tracked object";
      return planning::complete_object_request(all);
    }
    case proto::NextBestView::TARGET_NOT_SET: break;
  }
  return invalid_argument("target: give object_id, box, event_id, pending_id or workspace");
}

Result<planning::NextBestViewRequest> to_request(pipeline::WorkingMemory& memory, const proto::NextBestView& msg,
                                                 ontology::ClassCatalog* classes, std::string& description) {
  auto target = target_request(memory, msg, classes, description);
  if (!target) return target.error();
  planning::NextBestViewRequest& r = *target;
  switch (msg.constraint()) {
    case proto::NextBestView::CONSTRAINT_SPHERE: r.constraint.kind = planning::ConstraintKind::kSphere; break;
    case proto::NextBestView::CONSTRAINT_SHELL: r.constraint.kind = planning::ConstraintKind::kShell; break;
    case proto::NextBestView::CONSTRAINT_LIST: r.constraint.kind = planning::ConstraintKind::kList; break;
    default: r.constraint.kind = planning::ConstraintKind::kCap; break;
  }
  r.constraint.radius_max_m = msg.radius_m() > 0.0 ? msg.radius_m() : 0.7;
  if (msg.radius_min_m() > 0.0) r.constraint.radius_min_m = msg.radius_min_m();
  if (msg.max_polar_deg() > 0.0) r.constraint.max_polar_deg = msg.max_polar_deg();
  if (msg.samples() > 0) r.constraint.samples = static_cast<int>(std::min<std::uint32_t>(msg.samples(), 100001));
  r.constraint.up_world = memory.snapshot()->up_world;
  for (int i = 0; i < msg.poses_size(); ++i) {
    auto pose = convert::decode_pose(msg.poses(i), "poses[" + std::to_string(i) + "]");
    if (!pose) return pose.error();
    r.constraint.poses.push_back(*pose);
  }
  if (!msg.measure().empty()) {
    auto m = planning::parse_measure(msg.measure());
    if (!m) return invalid_argument("measure: unknown '" + msg.measure() + "' (" + planning::all_measure_names() + ")");
    r.measure = *m;
  }
  if (msg.n() > 0) r.n = static_cast<int>(std::min<std::uint32_t>(msg.n(), 1001));
  if (msg.has_intrinsics()) {
    auto K = convert::decode_intrinsics(msg.intrinsics(), "intrinsics");
    if (!K) return K.error();
    r.intrinsics = *K;
  }
  if (msg.has_current_pose()) {
    auto pose = convert::decode_pose(msg.current_pose(), "current_pose");
    if (!pose) return pose.error();
    r.current_T_world_camera = *pose;
    r.motion_cost_per_m = msg.motion_cost_per_m();
  }
  return target;
}

// The seed's planner (measure covariance*): one view, on the sphere of radius_m around an object.
Status covariance_view(const pipeline::WorkingMemory& memory, const proto::NextBestView& msg, planning::WeightRule rule,
                       proto::NextBestViewReply* out) {
  const std::string measure = planning::covariance_measure_name(rule);
  if (msg.target_case() != proto::NextBestView::kObjectId) {
    return invalid_argument("measure " + measure + ": plans from a tracked object's points; give object_id, not a box, "
                            "an event, a pending change or the workspace");
  }
  if (msg.constraint() != proto::NextBestView::CONSTRAINT_CAP && msg.constraint() != proto::NextBestView::CONSTRAINT_SPHERE) {
    return invalid_argument("constraint: measure " + measure + " plans on the sphere of radius_m (cap or sphere), not a shell or a list");
  }
  auto request = pipeline::covariance_view_request(memory, msg.object_id(), rule, msg.radius_m() > 0.0 ? msg.radius_m() : 0.7);
  if (!request) return request.error();
  if (msg.constraint() == proto::NextBestView::CONSTRAINT_CAP) {
    request->max_polar_deg = msg.max_polar_deg() > 0.0 ? msg.max_polar_deg() : planning::ViewConstraint{}.max_polar_deg;
  }
  auto answer = planning::covariance_next_view(*request);
  if (!answer) return answer.error();
  const auto snapshot = memory.snapshot();
  for (const auto& o : snapshot->objects) {
    if (o.id == msg.object_id()) convert::to_proto(o.cluster.box.aabb(), out->mutable_target());
  }
  out->set_target_description("the object's points and its box's faces (the seed's planner)");
  out->set_measure(measure);
  out->set_candidates(1);
  auto* v = out->add_views();
  convert::to_proto(answer->view.T_world_camera, v->mutable_pose());
  if (msg.has_current_pose()) {
    auto pose = convert::decode_pose(msg.current_pose(), "current_pose");
    if (!pose) return pose.error();
    v->set_motion_m((answer->view.T_world_camera.translation() - pose->translation()).norm());
  }
  v->set_why(convert::valid_utf8(answer->why));
  return {};
}

// The answer's views as the live view draws them: poses, scores, the target, the camera's field of view.
SuggestedViewSet suggested_set(const proto::NextBestView& msg, const proto::NextBestViewReply& reply) {
  SuggestedViewSet set;
  set.measure = reply.measure();
  if (auto box = convert::decode_box(reply.target(), "target")) set.target = *box;
  Intrinsics K = planning::NextBestViewRequest{}.intrinsics;
  if (msg.has_intrinsics()) {
    if (auto given = convert::decode_intrinsics(msg.intrinsics(), "intrinsics")) K = *given;
  }
  set.horizontal_fov_deg = 2.0 * std::atan(0.5 * K.width / K.fx) * 180.0 / M_PI;
  set.vertical_fov_deg = 2.0 * std::atan(0.5 * K.height / K.fy) * 180.0 / M_PI;
  for (const auto& v : reply.views()) {
    if (auto pose = convert::decode_pose(v.pose(), "pose")) set.views.push_back({*pose, v.score()});
  }
  return set;
}

Status answer_next_best_view(pipeline::WorkingMemory& memory, const proto::NextBestView& msg, ontology::ClassCatalog* classes,
                             proto::NextBestViewReply* out) {
  if (const auto rule = planning::parse_covariance_measure(msg.measure())) return covariance_view(memory, msg, *rule, out);
  std::string description;
  auto request = to_request(memory, msg, classes, description);
  if (!request) return request.error();
  auto region = planning::planning_region(*request);
  if (!region) return region.error();
  auto grid = memory.dense_grid(*region, kMaxPlanningVoxels);
  if (!grid) return grid.error();
  auto answer = planning::next_best_views(*grid, *request);
  if (!answer) return answer.error();
  convert::to_proto(request->target_world, out->mutable_target());
  if (answer->planned_for_box) {
    char text[200];
    if (answer->surface_coverage >= 1.0) {
      std::snprintf(text, sizeof text, "; every one of its %zu voxels is known, so the views are for its box", answer->surface_voxels);
    } else {
      std::snprintf(text, sizeof text,
                    "; no candidate reaches an unknown voxel of it (%zu voxels, coverage %.3f), so the views are for its box",
                    answer->surface_voxels, answer->surface_coverage);
    }
    description += text;
  }
  out->set_target_description(convert::valid_utf8(description));
  out->set_measure(planning::to_string(answer->measure));
  out->set_coverage(answer->coverage_now);
  out->set_target_voxels(answer->target_voxels);
  out->set_candidates(static_cast<std::uint32_t>(answer->candidates));
  for (const auto& v : answer->views) {
    auto* o = out->add_views();
    convert::to_proto(v.T_world_camera, o->mutable_pose());
    o->set_score(v.score);
    o->set_gain(v.gain.gain);
    o->set_expected_coverage(v.gain.expected_coverage);
    o->set_unknown_voxels(v.gain.unknown_reached);
    o->set_rear_side_voxels(v.gain.rear_side);
    o->set_motion_m(v.motion_m);
    o->set_why(convert::valid_utf8(v.why));
  }
  return {};
}

}  // namespace

Status next_best_view(pipeline::WorkingMemory& memory, const proto::NextBestView& msg, ontology::ClassCatalog* classes,
                      proto::NextBestViewReply* out, SuggestedViews* suggested) {
  Status status = answer_next_best_view(memory, msg, classes, out);
  if (status && suggested != nullptr) suggested->record(suggested_set(msg, *out));
  return status;
}

}  // namespace scenewatch::service
