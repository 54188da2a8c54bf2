// The calls that read the model: health, stats, planes, objects (described by their classes),
// hands, the pending changes, occupancy, the map, localization, and the event log with its
// subscription.
#include <algorithm>
#include <optional>

#include "class_records.h"
#include "ontology_convert.h"
#include "proto_convert.h"
#include "request_handler_impl.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"

#ifndef SCENEWATCH_VERSION
#define SCENEWATCH_VERSION "unknown"
#endif

namespace scenewatch::service {

namespace {

constexpr std::uint32_t kDefaultEventCount = 1000;
constexpr std::uint32_t kMaxEventCount = 10000;

}  // namespace

Status RequestHandler::Impl::health(proto::Response& response) {
  auto* out = response.mutable_health();
  out->set_version(SCENEWATCH_VERSION);
  out->set_uptime_s(uptime_s());
  out->set_frames_processed(memory.snapshot()->frames_processed);
  return {};
}

Status RequestHandler::Impl::stats(proto::Response& response) {
  const pipeline::Stats s = memory.stats();
  auto* out = response.mutable_stats();
  out->set_frames_processed(s.frames_processed);
  out->set_points_processed(s.points_processed);
  out->set_events_emitted(s.events_emitted);
  out->set_map_leaf_nodes(s.map_leaf_nodes);
  out->set_map_occupied_leaves(s.map_occupied_leaves);
  out->set_map_memory_bytes(s.map_memory_bytes);
  out->set_map_resolution_m(s.map_resolution_m);
  out->set_last_frame_ms(s.last_frame_ms);
  out->set_mean_frame_ms(s.mean_frame_ms);
  out->set_tracked_objects(s.tracked_objects);
  out->set_keyframes(s.keyframes);
  out->set_mesh_triangles(s.mesh_triangles);
  out->set_appearance_memory_bytes(s.appearance_memory_bytes);
  out->set_frames_skipped(frames_skipped.load());
  out->set_connections(connections ? static_cast<std::uint32_t>(connections()) : 0);
  out->set_uptime_s(uptime_s());
  return {};
}

Status RequestHandler::Impl::get_localization(const proto::GetLocalization& msg, proto::Response& response) {
  auto* out = response.mutable_localization();
  if (!msg.camera().empty() || msg.only_default()) {
    auto where = memory.localization(msg.camera());
    if (!where) return where.error();
    auto* camera = out->add_cameras();
    convert::to_proto(*where, camera);
    camera->set_camera(msg.camera());
    return {};
  }
  for (const auto& [name, where] : memory.localizations()) {
    auto* camera = out->add_cameras();
    convert::to_proto(where, camera);
    camera->set_camera(name);
  }
  return {};
}

Status RequestHandler::Impl::get_planes(proto::Response& response) {
  const auto snapshot = memory.snapshot();
  auto* out = response.mutable_planes();
  out->set_frames_processed(snapshot->frames_processed);
  out->set_last_stamp_s(snapshot->last_stamp_s);
  for (const auto& plane : snapshot->planes) convert::to_proto(plane, out->add_planes());
  return {};
}

Status RequestHandler::Impl::get_map(proto::Response& response) {
  const std::uint64_t frames = memory.snapshot()->frames_processed;
  pipeline::BinaryMap map = memory.binary_map();
  auto* out = response.mutable_map();
  out->set_resolution_m(map.resolution_m);
  out->set_binary_data(std::move(map.data));
  out->set_nodes(map.nodes);
  out->set_leaf_nodes(map.leaf_nodes);
  out->set_frames_processed(frames);
  return {};
}

Status RequestHandler::Impl::get_objects(const proto::GetObjects& msg, proto::Response& response) {
  const auto snapshot = memory.snapshot();
  const bool describe = msg.describe() && config.classes;
  std::vector<std::shared_ptr<const pipeline::ObjectClassInfo>> described;
  if (describe) {
    described = describe_and_record(memory, *snapshot, *config.classes);
  }
  auto* out = response.mutable_objects();
  out->set_frames_processed(snapshot->frames_processed);
  for (std::size_t k = 0; k < snapshot->objects.size(); ++k) {
    auto* o = out->add_objects();
    convert::to_proto(snapshot->objects[k], o);
    if (!describe) continue;
    auto* ontology = o->mutable_ontology();  // present, empty for an object without points
    if (described[k]) convert::to_proto(*described[k], ontology);
  }
  return {};
}

Status RequestHandler::Impl::get_hands(proto::Response& response) {
  const auto snapshot = memory.snapshot();
  const pipeline::HandsSeen& seen = snapshot->hands;
  auto* out = response.mutable_hands();
  out->set_frame_index(seen.frame_index);
  out->set_stamp_s(seen.stamp_s);
  for (const auto& h : seen.hands) {
    auto* o = out->add_hands();
    convert::to_proto(h.box_world, o->mutable_box_world());
    convert::to_proto(h.tip_world, o->mutable_tip_world());
    o->set_score(h.score);
    o->set_pixels(h.pixels);
    o->set_enters_from_border(h.enters_from_border);
  }
  out->set_person_pixels(seen.person_pixels);
  if (seen.person_box_world) convert::to_proto(*seen.person_box_world, out->mutable_person_box_world());
  return {};
}

Status RequestHandler::Impl::get_pending_changes(proto::Response& response) {
  const auto snapshot = memory.snapshot();
  auto* out = response.mutable_pending_changes();
  out->set_frames_processed(snapshot->frames_processed);
  for (const auto& seen : snapshot->pending) {
    const change::PendingChange& c = seen.change;
    auto* o = out->add_changes();
    o->set_id(c.id);
    o->set_kind(convert::to_proto(c.kind));
    convert::to_proto(c.box_world, o->mutable_box_world());
    convert::to_proto(c.centroid_world, o->mutable_centroid_world());
    o->set_hits(static_cast<std::uint32_t>(c.hits));
    o->set_hits_needed(static_cast<std::uint32_t>(c.hits_needed));
    o->set_camera(convert::valid_utf8(seen.camera));
  }
  return {};
}

Status RequestHandler::Impl::query_occupancy(const proto::QueryOccupancy& msg, proto::Response& response) {
  if (msg.points_size() == 0 && !msg.has_box()) return invalid_argument("give points, a box, or both");
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(msg.points_size()));
  for (int i = 0; i < msg.points_size(); ++i) {
    auto p = convert::decode_point(msg.points(i), "points[" + std::to_string(i) + "]");
    if (!p) return p.error();
    points.push_back(*p);
  }
  std::optional<Aabb> box;
  if (msg.has_box()) {
    auto b = convert::decode_box(msg.box(), "box");
    if (!b) return b.error();
    box = *b;
  }
  auto* out = response.mutable_occupancy();
  for (const auto& p : points) out->add_states(to_proto(memory.query(p)));
  if (box) {
    const background::BoxOccupancy summary = memory.query_box(*box);
    auto* b = out->mutable_box();
    b->set_state(to_proto(summary.state));
    b->set_occupied_voxels(summary.occupied_voxels);
    b->set_free_voxels(summary.free_voxels);
    b->set_unknown_voxels(summary.unknown_voxels);
  }
  return {};
}

proto::OccupancyState RequestHandler::Impl::to_proto(background::Occupancy state) {
  switch (state) {
    case background::Occupancy::kFree: return proto::OCCUPANCY_FREE;
    case background::Occupancy::kOccupied: return proto::OCCUPANCY_OCCUPIED;
    case background::Occupancy::kUnknown: break;
  }
  return proto::OCCUPANCY_UNKNOWN;
}

Status RequestHandler::Impl::subscribe(SessionContext* context, proto::Response& response) {
  if (context == nullptr || !context->event_sink) {
    return unavailable("this connection cannot receive pushed events");
  }
  // Subscribe first, then read the log: every later event is pushed, none is lost in between
  // (an event may be both in the log up to last_event_id and pushed; ids tell them apart).
  if (context->subscription < 0) {
    context->subscription = memory.subscribe([sink = context->event_sink](const Event& event) {
      proto::Response pushed;
      pushed.set_id(0);
      convert::to_proto(event, pushed.mutable_event());
      std::string bytes;
      pushed.SerializeToString(&bytes);
      sink(std::move(bytes));
    });
    localization_notices.add(context->subscription, context->event_sink);
  }
  const auto log = memory.events_since(0, std::max<std::size_t>(1, memory.config().max_event_log));
  response.mutable_subscribe()->set_last_event_id(log.empty() ? 0 : log.back().id);
  return {};
}

Status RequestHandler::Impl::get_events(const proto::GetEvents& msg, proto::Response& response) {
  const std::uint32_t count =
      msg.max_count() == 0 ? kDefaultEventCount : std::min(msg.max_count(), kMaxEventCount);
  auto* out = response.mutable_events();
  for (const auto& event : memory.events_since(msg.since(), count)) convert::to_proto(event, out->add_events());
  return {};
}

}  // namespace scenewatch::service
