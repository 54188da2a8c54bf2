#include "scenewatch/service/request_handler.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <optional>

#include <google/protobuf/util/json_util.h>

#include "live_frame.h"
#include "localization_notices.h"
#include "next_best_view_call.h"
#include "ontology_convert.h"
#include "proto_convert.h"
#include "scenewatch.pb.h"
#include "scenewatch/core/files.h"
#include "scenewatch/service/access_token.h"
#include "scenewatch/service/model_directory.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"

#ifndef SCENEWATCH_VERSION
#define SCENEWATCH_VERSION "unknown"
#endif

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

constexpr std::uint32_t kDefaultEventCount = 1000;
constexpr std::uint32_t kMaxEventCount = 10000;

/// Where a call runs: see the class comment of RequestHandler.
enum class Route { kInline, kQuery, kMutate };

Route route_of(proto::Request::CallCase call) {
  switch (call) {
    case proto::Request::kQueryOccupancy:
    case proto::Request::kStats:
    case proto::Request::kGetLocalization:
    case proto::Request::kGetSurpriseMap:
    case proto::Request::kNextBestView:
    case proto::Request::kGetMap:
      return Route::kQuery;
    case proto::Request::kIngestFrame:
    case proto::Request::kIngestFile:
    case proto::Request::kClearBox:
    case proto::Request::kReset:
    case proto::Request::kSaveModel:
    case proto::Request::kLoadModel:
    case proto::Request::kDefineClass:
      return Route::kMutate;
    default:
      return Route::kInline;
  }
}

/// Name of the request's call as in the .proto ("ingest_frame"), for messages and logs.
std::string call_name(const proto::Request& request) {
  if (request.call_case() == proto::Request::CALL_NOT_SET) return "none";
  const auto* field = proto::Request::descriptor()->FindFieldByNumber(request.call_case());
  return field != nullptr ? field->name() : "unknown";
}

Error permission_denied(std::string message) { return {ErrorCode::kPermissionDenied, std::move(message)}; }
Error unavailable(std::string message) { return {ErrorCode::kUnavailable, std::move(message)}; }

/// True when `path` equals `root` or lies below it (component-wise, both canonical).
bool is_within(const fs::path& path, const fs::path& root) {
  auto [root_it, path_it] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  return root_it == root.end();
}

/// Absolute, symlink-resolved, without a trailing separator.
fs::path canonical_root(const fs::path& root) {
  std::error_code ec;
  fs::path out = fs::weakly_canonical(fs::absolute(root, ec), ec);
  if (ec) out = fs::absolute(root).lexically_normal();
  if (!out.has_filename() && out.has_relative_path()) out = out.parent_path();
  return out;
}

Reply finish(proto::Response& response, std::string call) {
  Reply reply;
  reply.call = std::move(call);
  reply.ok = response.status().code() == proto::Status::OK;
  if (!reply.ok) reply.error = response.status().message();
  response.SerializeToString(&reply.payload);
  return reply;
}

Reply error_reply(std::uint64_t id, proto::Status::Code code, const std::string& message, std::string call) {
  proto::Response response;
  response.set_id(id);
  response.mutable_status()->set_code(code);
  response.mutable_status()->set_message(convert::valid_utf8(message));
  return finish(response, std::move(call));
}

}  // namespace

struct RequestHandler::Impl {
  pipeline::WorkingMemory& memory;
  HandlerConfig config;
  Executor mutate, query;
  std::function<std::size_t()> connections;
  FrameObserver frame_observer;
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> frames_skipped{0};  // live frames superseded by newer ones
  LocalizationNotices localization_notices;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();

  Impl(pipeline::WorkingMemory& m, HandlerConfig c, Executor mu, Executor q)
      : memory(m), config(std::move(c)), mutate(std::move(mu)), query(std::move(q)) {
    for (auto& root : config.data_roots) root = canonical_root(root);
  }

  double uptime_s() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }

  /// Decodes a request and runs it inline or on its executor; see RequestHandler::handle().
  void handle(std::string payload, SessionContext& context, std::function<void(Reply)> done,
              bool use_executors) {
    auto request = std::make_shared<proto::Request>();
    if (!request->ParseFromString(payload)) {
      done(error_reply(0, proto::Status::INVALID_ARGUMENT,
                       "request of " + std::to_string(payload.size()) +
                           " bytes is not a valid scenewatch.proto.Request message",
                       "unparseable"));
      return;
    }
    if (request->call_case() == proto::Request::CALL_NOT_SET) {
      done(error_reply(request->id(), proto::Status::UNKNOWN_REQUEST,
                       "request " + std::to_string(request->id()) +
                           " has no call set (empty, or a call this server does not know)",
                       "none"));
      return;
    }
    payload = std::string();  // an ingest payload can be large: free it before the work is queued
    const Route route = route_of(request->call_case());
    if (route == Route::kMutate && !config.token.empty() && !tokens_equal(request->token(), config.token)) {
      const std::string call = call_name(*request);
      done(error_reply(request->id(), proto::Status::PERMISSION_DENIED,
                       call + ": this call changes the model and needs the daemon's token (Request.token, the "
                       "contents of the daemon's token file; the CLI reads it with --token-file): " +
                           (request->token().empty() ? std::string("the request carries none")
                                                     : std::string("the request's token is wrong")),
                       call));
      return;
    }
    const Executor& executor = route == Route::kMutate ? mutate : query;
    if (!use_executors || route == Route::kInline || !executor) {
      done(execute(*request, &context));
      return;
    }
    if (request->call_case() == proto::Request::kIngestFrame) {
      // Decoded here, on the connection's thread, while the frame before it may still be
      // processing on the model's strand (a client may send the next frame before the reply).
      auto frame = std::make_shared<const Result<Frame>>(decode_frame(request->ingest_frame()));
      executor([this, request, frame, done = std::move(done)] { done(execute(*request, nullptr, frame.get())); });
      return;
    }
    executor([this, request, done = std::move(done)] { done(execute(*request, nullptr)); });
  }

  /// Runs one call and encodes its response. `context` is null off the connection's thread;
  /// `decoded`, when given, is the request's IngestFrame decoded already.
  Reply execute(const proto::Request& request, SessionContext* context, const Result<Frame>* decoded = nullptr) {
    proto::Response response;
    response.set_id(request.id());
    std::string call = call_name(request);
    Status status;
    try {
      status = dispatch(request, context, response, decoded);
    } catch (const std::exception& e) {
      // A bug or out of memory: answer the client, keep serving the others.
      status = Error{ErrorCode::kInternal, std::string("unexpected exception: ") + e.what()};
    }
    if (!status) {
      response.clear_result();
      const Error& e = status.error();
      response.mutable_status()->set_code(convert::to_proto(e.code));
      response.mutable_status()->set_message(convert::valid_utf8(call + ": " + e.message));
    }
    return finish(response, std::move(call));
  }

  Status dispatch(const proto::Request& request, SessionContext* context, proto::Response& response,
                  const Result<Frame>* decoded) {
    if (route_of(request.call_case()) == Route::kMutate && stopping) {
      return unavailable("the server is shutting down");
    }
    switch (request.call_case()) {
      case proto::Request::kHealth: return health(response);
      case proto::Request::kStats: return stats(response);
      case proto::Request::kIngestFrame:
        if (decoded == nullptr) return ingest_frame(request.ingest_frame(), response);
        if (!*decoded) return decoded->error();
        return process(**decoded, response);
      case proto::Request::kIngestFile: return ingest_file(request.ingest_file(), response);
      case proto::Request::kGetPlanes: return get_planes(response);
      case proto::Request::kGetObjects: return get_objects(request.get_objects(), response);
      case proto::Request::kGetHands: return get_hands(response);
      case proto::Request::kQueryOccupancy: return query_occupancy(request.query_occupancy(), response);
      case proto::Request::kClearBox: return clear_box(request.clear_box(), response);
      case proto::Request::kReset:
        memory.reset();
        localization_notices.forget_cameras();
        response.mutable_reset();
        return {};
      case proto::Request::kSaveModel: return save_model(response);
      case proto::Request::kLoadModel: return load_model(response);
      case proto::Request::kSubscribe: return subscribe(context, response);
      case proto::Request::kGetEvents: return get_events(request.get_events(), response);
      case proto::Request::kGetSurpriseMap: return get_surprise_map(request.get_surprise_map(), response);
      case proto::Request::kDefineClass: return define_class(request.define_class(), response);
      case proto::Request::kListClasses: return list_classes(response);
      case proto::Request::kGetLocalization: return get_localization(request.get_localization(), response);
      case proto::Request::kGetMap: return get_map(response);
      case proto::Request::kNextBestView:
        return service::next_best_view(memory, request.next_best_view(), response.mutable_next_best_view());
      case proto::Request::CALL_NOT_SET: break;
    }
    // Not reached for a known call: the empty oneof is answered by the caller.
    return Error{ErrorCode::kInternal, "unhandled call"};
  }

  Status health(proto::Response& response) {
    auto* out = response.mutable_health();
    out->set_version(SCENEWATCH_VERSION);
    out->set_uptime_s(uptime_s());
    out->set_frames_processed(memory.snapshot()->frames_processed);
    return {};
  }

  Status stats(proto::Response& response) {
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

  Status get_localization(const proto::GetLocalization& msg, proto::Response& response) {
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

  static Result<Frame> decode_frame(const proto::IngestFrame& msg) {
    if (!msg.has_cloud()) return invalid_argument("cloud is missing");
    auto cloud = convert::decode_cloud(msg.cloud());
    if (!cloud) return cloud.error();
    Frame frame;
    frame.cloud = cloud->cloud;
    frame.has_color = cloud->has_color;
    if (msg.has_pose()) {
      auto pose = convert::decode_pose(msg.pose(), "pose");
      if (!pose) return pose.error();
      frame.T_world_camera = *pose;
    }
    if (msg.has_intrinsics()) {
      auto k = convert::decode_intrinsics(msg.intrinsics(), "intrinsics");
      if (!k) return k.error();
      if (frame.cloud->height > 1 && (static_cast<std::uint32_t>(k->width) != frame.cloud->width ||
                                      static_cast<std::uint32_t>(k->height) != frame.cloud->height)) {
        return invalid_argument("intrinsics are for a " + std::to_string(k->width) + " x " +
                                std::to_string(k->height) + " image but the organized cloud is " +
                                std::to_string(frame.cloud->width) + " x " + std::to_string(frame.cloud->height));
      }
      frame.intrinsics = *k;
    }
    if (!std::isfinite(msg.stamp_s())) return invalid_argument("stamp_s is not finite");
    frame.stamp_s = msg.stamp_s();
    frame.source = convert::source_label(msg.source());
    frame.camera = msg.camera();  // checked by the working memory with the rest of the frame
    auto mode = convert::decode_localization_mode(msg.localization());
    if (!mode) return mode.error();
    frame.localization = *mode;
    return frame;
  }

  Status ingest_frame(const proto::IngestFrame& msg, proto::Response& response) {
    auto frame = decode_frame(msg);
    if (!frame) return frame.error();
    return process(*frame, response);
  }

  Status get_surprise_map(const proto::GetSurpriseMap& msg, proto::Response& response) {
    std::shared_ptr<const pipeline::SurpriseResult> result;
    if (msg.has_frame()) {
      auto frame = decode_frame(msg.frame());
      if (!frame) return frame.error();
      auto computed = memory.surprise(*frame);
      if (!computed) return computed.error();
      result = *computed;
    } else {
      result = memory.last_surprise();
      if (!result) return not_found("no surprise map yet: ingest posed RGB-D frames (the first one becomes a keyframe)");
    }
    auto* out = response.mutable_surprise_map();
    const auto& map = result->map;
    out->set_width(static_cast<std::uint32_t>(map.width));
    out->set_height(static_cast<std::uint32_t>(map.height));
    out->set_total(convert::encode_floats(map.total));
    if (msg.include_channels()) {
      for (const auto& channel : map.channel) out->add_channels(convert::encode_floats(channel));
    }
    out->set_known_pixels(map.known_pixels);
    out->set_reference_views(static_cast<std::uint32_t>(result->reference_views));
    for (const auto& event : result->events) convert::to_proto(event, out->add_regions());
    convert::to_proto(result->T_world_camera, out->mutable_pose());
    convert::to_proto(result->intrinsics, out->mutable_intrinsics());
    out->set_stamp_s(result->stamp_s);
    out->set_compute_ms(result->ms);
    return {};
  }

  // Opens a client's path beneath the data root it names. The path is matched to a root as
  // written (`..` folded) and, failing that or when it crosses a symlink the kernel will not follow
  // beneath a root (an absolute one), with its symlinks resolved. Either way the kernel opens it
  // beneath the root (open_beneath): a symlink swapped in after the match cannot lead out.
  Result<FileBeneath> open_under_roots(const fs::path& requested) const {
    if (config.data_roots.empty()) {
      return permission_denied("reading files on the server is disabled: no data roots are configured "
                               "(server.data_roots)");
    }
    std::optional<Error> refused;
    auto open_as = [&](const fs::path& candidate) -> std::optional<Result<FileBeneath>> {
      for (const auto& root : config.data_roots) {
        if (candidate.empty() || !is_within(candidate, root)) continue;
        auto file = open_beneath(root, candidate.lexically_relative(root));
        if (file || file.error().code != ErrorCode::kPermissionDenied) return file;
        refused = file.error();
      }
      return std::nullopt;
    };
    if (auto file = open_as(requested.lexically_normal())) return std::move(*file);
    std::error_code ec;  // only now the file system: the path's symlinks resolved
    if (auto file = open_as(fs::weakly_canonical(requested, ec))) return std::move(*file);
    std::string roots;
    for (const auto& root : config.data_roots) roots += (roots.empty() ? "" : ", ") + root.string();
    return permission_denied("'" + requested.string() + "' is outside the data roots (" + roots + ")" +
                             (refused ? ": " + refused->message : std::string()));
  }

  Status ingest_file(const proto::IngestFile& msg, proto::Response& response) {
    if (msg.path().empty()) return invalid_argument("path is empty");
    const fs::path requested(msg.path());
    if (!requested.is_absolute()) return invalid_argument("path must be absolute, got '" + msg.path() + "'");
    auto file = open_under_roots(requested);
    if (!file) return file.error();
    if (file->size() > config.max_file_bytes) {
      return invalid_argument("'" + msg.path() + "' is " + std::to_string(file->size()) +
                              " bytes, more than server.max_file_bytes (" + std::to_string(config.max_file_bytes) + ")");
    }
    auto frame = io::load_cloud_frame(file->alias());
    if (!frame) {
      // Name the file the client asked for, not the private alias it was read through.
      Error e = frame.error();
      const std::string alias = file->alias().string();
      for (auto at = e.message.find(alias); at != std::string::npos; at = e.message.find(alias)) {
        e.message.replace(at, alias.size(), msg.path());
      }
      return e;
    }
    frame->source = msg.path();
    if (msg.has_pose()) {
      auto pose = convert::decode_pose(msg.pose(), "pose");
      if (!pose) return pose.error();
      frame->T_world_camera = *pose;
    }
    if (!std::isfinite(msg.stamp_s())) return invalid_argument("stamp_s is not finite");
    frame->stamp_s = msg.stamp_s();
    return process(*frame, response);
  }

  Status process(const Frame& frame, proto::Response& response) {
    auto result = memory.process(frame);
    if (!result) return result.error();
    if (frame_observer) frame_observer(frame, *result);
    localization_notices.after_frame(frame.camera, result->localization);
    auto* out = response.mutable_ingest();
    out->set_frame_index(result->frame_index);
    out->set_points(result->points);
    for (const auto& plane : result->planes) convert::to_proto(plane, out->add_planes());
    for (const auto& cluster : result->objects) convert::to_proto(cluster, out->add_clusters());
    for (const auto& event : result->events) convert::to_proto(event, out->add_events());
    out->set_segment_ms(result->segment_ms);
    out->set_insert_ms(result->insert_ms);
    out->set_total_ms(result->total_ms);
    out->set_frames_skipped(frames_skipped.load());
    convert::to_proto(result->localization, out->mutable_localization());
    return {};
  }

  Status get_planes(proto::Response& response) {
    const auto snapshot = memory.snapshot();
    auto* out = response.mutable_planes();
    out->set_frames_processed(snapshot->frames_processed);
    out->set_last_stamp_s(snapshot->last_stamp_s);
    for (const auto& plane : snapshot->planes) convert::to_proto(plane, out->add_planes());
    return {};
  }

  Status get_map(proto::Response& response) {
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

  Status get_objects(const proto::GetObjects& msg, proto::Response& response) {
    const auto snapshot = memory.snapshot();
    const bool describe = msg.describe() && config.classes;
    std::vector<std::shared_ptr<const pipeline::ObjectClassInfo>> described;
    if (describe) {
      described = memory.describe_objects(*snapshot, *config.classes,
                                          [this](const TrackedObject& object, const pipeline::ObjectClassInfo& info) {
                                            record(object, info);
                                          });
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

  // Each new description is an instance seen (class, the fitted primitive as JSON, when the object
  // was last seen); a handled object's learnt free DoFs also teach its class's motions. The catalog
  // queues the writes for its own thread: nothing here waits for the disk.
  void record(const TrackedObject& object, const pipeline::ObjectClassInfo& described) {
    proto::ObjectClassInfo info;
    convert::to_proto(described, &info);
    ontology::InstanceRecord instance;
    instance.class_name = info.class_name();
    instance.time_s = object.last_seen_s;
    google::protobuf::util::JsonPrintOptions options;
    options.preserve_proto_field_names = true;
    if (info.has_primitive() && !google::protobuf::util::MessageToJsonString(info.primitive(), &instance.parameters_json, options).ok()) {
      instance.parameters_json.clear();
    }
    if (instance.parameters_json.empty()) instance.parameters_json = "{}";
    std::optional<DofFlags> handled_free;
    if (object.foreground && !object.foreground->handlings.empty()) handled_free = object.foreground->free;
    config.classes->record(instance, handled_free);
  }

  Status get_hands(proto::Response& response) {
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

  Status query_occupancy(const proto::QueryOccupancy& msg, proto::Response& response) {
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

  static proto::OccupancyState to_proto(background::Occupancy state) {
    switch (state) {
      case background::Occupancy::kFree: return proto::OCCUPANCY_FREE;
      case background::Occupancy::kOccupied: return proto::OCCUPANCY_OCCUPIED;
      case background::Occupancy::kUnknown: break;
    }
    return proto::OCCUPANCY_UNKNOWN;
  }

  Status clear_box(const proto::ClearBox& msg, proto::Response& response) {
    if (!msg.has_box()) return invalid_argument("box is missing");
    auto box = convert::decode_box(msg.box(), "box");
    if (!box) return box.error();
    response.mutable_clear_box()->set_voxels_changed(memory.clear_box(*box));
    return {};
  }

  Status require_model_dir() const {
    if (config.model_dir.empty()) {
      return unavailable("no model directory is configured (server.model_dir or --model-dir)");
    }
    return {};
  }

  Status save_model(proto::Response& response) {
    if (Status s = require_model_dir(); !s) return s;
    if (Status s = service::save_model(memory, config.model_dir, config.keep_snapshots); !s) return s;
    response.mutable_save_model()->set_model_dir(config.model_dir.string());
    return {};
  }

  Status require_classes() const {
    if (!config.classes) return unavailable("this server has no object classes loaded");
    return {};
  }

  Status define_class(const proto::DefineClass& msg, proto::Response& response) {
    if (Status s = require_classes(); !s) return s;
    auto parsed = ontology::parse_classes(msg.yaml(), "define_class.yaml");
    if (!parsed) return parsed.error();
    if (parsed->empty()) return invalid_argument("define_class.yaml: classes: the list is empty");
    const double now_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    auto* out = response.mutable_define_class();
    for (const auto& c : parsed->classes()) {
      if (Status s = config.classes->define(c, now_s); !s) return s;
      out->add_defined(c.name);
    }
    out->set_persisted(config.classes->persistent());
    return {};
  }

  Status list_classes(proto::Response& response) {
    if (Status s = require_classes(); !s) return s;
    const ontology::ClassLibrary library = config.classes->library();
    auto* out = response.mutable_list_classes();
    const auto learnt = config.classes->learnt();
    for (const auto& c : library.classes()) {
      const auto found = learnt.find(c.name);
      convert::to_proto(c, found == learnt.end() ? nullptr : &found->second, out->add_classes());
    }
    out->set_yaml(ontology::to_yaml(library.classes()));
    return {};
  }

  Status load_model(proto::Response& response) {
    if (Status s = require_model_dir(); !s) return s;
    if (Status s = memory.load(config.model_dir); !s) return s;
    localization_notices.forget_cameras();
    auto* out = response.mutable_load_model();
    out->set_model_dir(config.model_dir.string());
    out->set_objects(memory.snapshot()->objects.size());
    return {};
  }

  Status subscribe(SessionContext* context, proto::Response& response) {
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

  Status get_events(const proto::GetEvents& msg, proto::Response& response) {
    const std::uint32_t count =
        msg.max_count() == 0 ? kDefaultEventCount : std::min(msg.max_count(), kMaxEventCount);
    auto* out = response.mutable_events();
    for (const auto& event : memory.events_since(msg.since(), count)) convert::to_proto(event, out->add_events());
    return {};
  }
};

RequestHandler::RequestHandler(pipeline::WorkingMemory& memory, HandlerConfig config, Executor mutate,
                               Executor query)
    : impl_(std::make_unique<Impl>(memory, std::move(config), std::move(mutate), std::move(query))) {}

RequestHandler::~RequestHandler() = default;

void RequestHandler::handle(std::string payload, SessionContext& context, std::function<void(Reply)> done) {
  impl_->handle(std::move(payload), context, std::move(done), /*use_executors=*/true);
}

bool RequestHandler::is_ingest_frame(std::string_view payload) const { return peek_live_frame(payload).frame; }

bool RequestHandler::is_live_frame(std::string_view payload) const {
  // A frame without the right token is not skipped: it is refused like any other.
  const LiveFramePeek peek = peek_live_frame(payload);
  return peek.live && (impl_->config.token.empty() || tokens_equal(peek.token, impl_->config.token));
}

Reply RequestHandler::skip_live_frame(std::string_view payload) {
  proto::Response response;
  response.set_id(peek_live_frame(payload).id);
  auto* out = response.mutable_ingest();
  out->set_skipped(true);
  out->set_frames_skipped(++impl_->frames_skipped);
  return finish(response, "ingest_frame (live, skipped: a newer frame was waiting)");
}

Reply RequestHandler::handle_now(const std::string& payload, SessionContext& context) {
  Reply out;
  impl_->handle(payload, context, [&out](Reply reply) { out = std::move(reply); }, /*use_executors=*/false);
  return out;
}

void RequestHandler::unsubscribe(SessionContext& context) {
  if (context.subscription >= 0) {
    impl_->memory.unsubscribe(context.subscription);
    impl_->localization_notices.remove(context.subscription);
    context.subscription = -1;
  }
}

std::string RequestHandler::error_payload(ErrorCode code, const std::string& message) const {
  return error_reply(0, convert::to_proto(code), message, "connection").payload;
}

void RequestHandler::set_frame_observer(FrameObserver observer) { impl_->frame_observer = std::move(observer); }

void RequestHandler::set_connection_counter(std::function<std::size_t()> counter) {
  impl_->connections = std::move(counter);
}

void RequestHandler::shutdown() { impl_->stopping = true; }

const HandlerConfig& RequestHandler::config() const { return impl_->config; }

}  // namespace scenewatch::service
